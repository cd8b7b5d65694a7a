"""The first day's surprises against Debian's ROS: the README's talker and the same loop
bare stop on Ctrl-C as under Debian's rospy (exit 0, nothing printed)."""

from __future__ import annotations

import pytest

from integration.test_first_day import BARE_LOOP, ctrl_c, readme_talker
from support import PYTHON, REFERENCE_PYTHON, reference_env, ros_env

pytestmark = pytest.mark.interop


@pytest.mark.parametrize("script", ["readme", "bare"])
@pytest.mark.parametrize("python", ["debian", "minros"])
def test_ctrl_c_on_a_talker_as_under_debian(debian_rosmaster, ros_home, tmp_path, script,
                                            python):
    path = tmp_path / "talker.py"
    path.write_text(readme_talker() if script == "readme" else BARE_LOOP)
    env = ros_env(debian_rosmaster, ros_home)
    if python == "debian":
        status, out = ctrl_c(path, reference_env(env), REFERENCE_PYTHON)
        if status is None:
            # rospy's own deadlock: the SIGINT handler's signal_shutdown calls the master
            # through the ServerProxy whose lock the interrupted main thread holds (loginfo
            # asks the master for /rosout_disable_topics_generation each time, uncached when
            # unset); 3 of 8 runs on this machine, stacks taken with faulthandler
            pytest.xfail("Debian's rospy deadlocked in its SIGINT handler")
    else:
        status, out = ctrl_c(path, env, PYTHON)
    assert status == 0, out
    assert "Traceback" not in out and "Exception" not in out, out
