"""diagnostic_updater: minros's statuses equal ROS 1's (Debian python3-diagnostic-updater) for
one scenario of tasks, composites, frequency and timestamp checks, topic diagnostics, diagnosed
publishers, hardware id, update period, removal and broadcast; and ROS 1's rostopic reads what
a minros Updater publishes on /diagnostics."""

from __future__ import annotations

import json
import subprocess
from pathlib import Path

import pytest

from support import PYTHON, REFERENCE_PYTHON, Proc, reference_env, require_reference, ros_env

pytestmark = pytest.mark.interop

FEED = Path(__file__).resolve().parent / "diagnostic_updater_feed.py"


def _feed(python: str, env) -> list:
    done = subprocess.run([python, str(FEED)], env=env, capture_output=True, text=True, timeout=60)
    assert done.returncode == 0, done.stderr
    return [json.loads(line) for line in done.stdout.splitlines()]


def test_statuses_equal_ros1s() -> None:
    require_reference()
    reference = _feed(REFERENCE_PYTHON, reference_env({}))
    ours = _feed(PYTHON, None)
    assert ours == reference
    arrays = reference[:-1]
    # the scenario covers what it claims: start-up messages, six updates, one timed update, the
    # broadcast, and warnings, errors and OKs among them
    assert sum(1 for a in arrays if a["status"][0][2] == "Node starting up") == 9
    levels = {s[1] for a in arrays for s in a["status"]}
    assert levels == {0, 1, 2}
    assert arrays[-1]["status"][0][1:3] == [2, "shutting down"]
    assert reference[-1] == {"image_pub": 27}


NODE = r'''
import rospy
import diagnostic_updater
rospy.init_node("diag_node")
updater = diagnostic_updater.Updater()
updater.setHardwareID("none")
updater.add(diagnostic_updater.Heartbeat())
rate = rospy.Rate(20)
print("updating", flush=True)
while not rospy.is_shutdown():
    updater.force_update()
    rate.sleep()
'''


def test_ros1_reads_a_minros_updater(tmp_path: Path, debian_rosmaster: int, ros_home: Path) -> None:
    script = tmp_path / "diag_node.py"
    script.write_text(NODE)
    node = Proc([PYTHON, str(script)], ros_env(debian_rosmaster, ros_home))
    try:
        node.read_until("updating", 30)
        env = reference_env(ros_env(debian_rosmaster, ros_home))
        echo = subprocess.run(["/usr/bin/rostopic", "echo", "-n", "1", "/diagnostics/status[0]"],
                              env=env, capture_output=True, text=True, timeout=60)
        assert echo.returncode == 0, echo.stderr
        assert echo.stdout == ('level: 0\nname: "diag_node: Heartbeat"\nmessage: "Alive"\n'
                               'hardware_id: "none"\nvalues: []\n---\n')
    finally:
        node.stop()


STAR = ("import json\nfrom diagnostic_updater import *\n"
        "print(json.dumps(sorted(k for k in dir() if not k.startswith('__') and k != 'json')))\n")


def test_star_import_gives_what_ros1s_gives() -> None:
    """``from diagnostic_updater import *`` then ``DiagnosticStatus.OK``, ``KeyValue(...)``, as
    ROS's examples write it: the same names as Debian's package, messages and modules included."""
    require_reference()
    names = [json.loads(subprocess.run([python, "-c", STAR], env=env, capture_output=True, text=True,
                                       timeout=60, check=True).stdout)
             for python, env in ((PYTHON, None), (REFERENCE_PYTHON, reference_env({})))]
    assert names[0] == names[1]
    assert {"DiagnosticStatus", "KeyValue", "DiagnosticArray", "rospy"} <= set(names[0])
