"""actionlib_tools' headless axclient against a Debian action server, its YAML helpers and
resource_retriever against Debian's modules."""

from __future__ import annotations

import json
import subprocess
from pathlib import Path

import pytest

from support import (
    PYTHON,
    REFERENCE_PYTHON,
    Proc,
    need,
    reference_env,
    reference_imports,
    ros_env,
)

pytestmark = pytest.mark.interop

ROSRUN = str(Path(PYTHON).parent / "rosrun")

SERVER = r'''
import rospy, actionlib
from actionlib.msg import TwoIntsAction, TwoIntsResult, TwoIntsFeedback
rospy.init_node("count_server")
def execute(goal):
    for _ in range(goal.a):
        server.publish_feedback(TwoIntsFeedback())
        rospy.sleep(0.05)
    if goal.b < 0:
        server.set_aborted(TwoIntsResult(sum=-1))
    else:
        server.set_succeeded(TwoIntsResult(sum=goal.a + goal.b))
server = actionlib.SimpleActionServer("/count", TwoIntsAction, execute, auto_start=False)
server.start()
print("server ready", flush=True)
rospy.spin()
'''


def test_axclient_sends_a_yaml_goal_to_a_debian_server(tmp_path: Path, debian_rosmaster: int,
                                                       ros_home: Path) -> None:
    script = tmp_path / "server.py"
    script.write_text(SERVER)
    env = ros_env(debian_rosmaster, ros_home)
    server = Proc([REFERENCE_PYTHON, str(script)], reference_env(env))
    try:
        server.read_until("server ready", 30)
        done = subprocess.run([ROSRUN, "actionlib_tools", "axclient.py", "/count",
                               "--goal", "{a: 2, b: 40}"], env=env, capture_output=True,
                              text=True, timeout=60)
        assert done.returncode == 0, done.stdout + done.stderr
        assert "feedback:" in done.stdout and "state: SUCCEEDED" in done.stdout, done.stdout
        assert "result:\n  sum: 42" in done.stdout, done.stdout
        aborted = subprocess.run([ROSRUN, "actionlib_tools", "axclient.py", "/count",
                                  "actionlib/TwoIntsAction", "--goal", "{a: 0, b: -5}"],
                                 env=env, capture_output=True, text=True, timeout=60)
        assert aborted.returncode == 1 and "state: ABORTED" in aborted.stdout, aborted
        bad = subprocess.run([ROSRUN, "actionlib_tools", "axclient.py", "/count",
                              "--goal", "{nosuchfield: 1}"], env=env, capture_output=True,
                             text=True, timeout=60)
        assert bad.returncode == 2 and bad.stderr.startswith("error: the goal does not fit "
                                                             "actionlib/TwoIntsGoal"), bad
        assert "Traceback" not in bad.stderr
    finally:
        server.stop()


COMPARE = r'''
import json, sys
from actionlib_tools.library import yaml_msg_str, yaml_msgs_str
from actionlib.msg import TwoIntsGoal
import resource_retriever
out = {
    "one": str(yaml_msg_str(TwoIntsGoal, "a: 3\nb: 4")),
    "file": resource_retriever.get_filename("package://actionlib/action/TwoInts.action", False).endswith("/actionlib/action/TwoInts.action"),
    "bytes": resource_retriever.get("package://actionlib/action/TwoInts.action").decode(),
    "plain": resource_retriever.get_filename("file:///tmp/x"),
}
try:
    yaml_msg_str(TwoIntsGoal, "[1, 2]")
except ValueError as exc:
    out["error"] = str(exc)
print(json.dumps(out))
'''


def test_yaml_helpers_and_resource_retriever_answer_as_debians() -> None:
    need(reference_imports("actionlib_tools.library, resource_retriever"),
         "Debian's python3-actionlib-tools/python3-resource-retriever are not installed",
         "scripts/install-ros-reference.sh")
    debian = subprocess.run([REFERENCE_PYTHON, "-c", COMPARE], env=reference_env({}),
                            capture_output=True, text=True, timeout=60)
    assert debian.returncode == 0, debian.stderr
    ours = subprocess.run([PYTHON, "-c", COMPARE], capture_output=True, text=True, timeout=60)
    assert ours.returncode == 0, ours.stderr
    assert json.loads(ours.stdout) == json.loads(debian.stdout)
    # Debian's yaml_msgs_str hands fill_message_args a dict where it takes a list (KeyError);
    # ours fills each message
    from actionlib.msg import TwoIntsGoal
    from actionlib_tools.library import yaml_msgs_str

    assert [(m.a, m.b) for m in yaml_msgs_str(TwoIntsGoal, "- {a: 1}\n- {b: 2}")] == [(1, 0), (0, 2)]
