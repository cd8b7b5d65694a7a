"""Seed "Opencv-Ros" across implementations: the same unmodified scripts, one side on Debian's
rospy + python3-cv-bridge, the other on minros (fake camera/imshow as in test_video_example.py)."""

from __future__ import annotations

import pytest
from test_video_example import FAKECAM, VIDEO, check_shown_frame, shown_count

from support import (
    PYTHON,
    REFERENCE_PYTHON,
    Proc,
    reference_env,
    require_reference,
    ros_env,
    wait_until,
)

pytestmark = pytest.mark.interop


@pytest.mark.parametrize("publisher_side", ["debian", "minros"])
def test_video_between_debian_and_minros(publisher_side, minros_core, ros_home, tmp_path):
    require_reference()
    out = tmp_path / "fakecam"
    out.mkdir()
    extra = {"PYTHONPATH": str(FAKECAM), "FAKECAM_DIR": str(out)}
    minros_env = ros_env(minros_core, ros_home, extra)
    debian_env = reference_env(ros_env(minros_core, ros_home))
    debian_env.update(extra)  # only the shim directory, nothing of minros
    sides = {"debian": (REFERENCE_PYTHON, debian_env), "minros": (PYTHON, minros_env)}
    sub_side = "minros" if publisher_side == "debian" else "debian"
    sub = Proc([sides[sub_side][0], str(VIDEO / "video_sub.py")], sides[sub_side][1])
    pub = Proc([sides[publisher_side][0], str(VIDEO / "video_pub.py")], sides[publisher_side][1])
    sub_out = ""  # a read_until that fails must not be hidden by the finally below
    try:
        sub_out = sub.read_until("receiving video frame", timeout=30)
        wait_until(lambda: shown_count(out) >= 3, timeout=15, what="three frames shown")
    finally:
        pub_out = pub.stop()
        sub_out += sub.stop()
    assert "publishing video frame" in pub_out
    assert "Traceback" not in pub_out + sub_out
    check_shown_frame(out / "camera.png")
