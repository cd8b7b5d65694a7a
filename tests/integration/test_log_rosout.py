"""Node logging end to end: console lines on stdout/stderr and rosgraph_msgs/Log on /rosout."""

from __future__ import annotations

import json
import re
from pathlib import Path

import pytest

from support import PYTHON, Proc, ros_env

TALKER = r'''
import rospy
from std_msgs.msg import String
rospy.init_node("log_talker")
pub = rospy.Publisher("/chatter", String, queue_size=1)
sub = rospy.Subscriber("/ignored", String, lambda m: None)
rospy.logdebug("debug is filtered at the default level")
class Speaker:
    def speak(self, i):
        rospy.logwarn("warning %d", i)
i = 0
while not rospy.is_shutdown():
    rospy.loginfo("hello %d", i)
    Speaker().speak(i)
    i += 1
    rospy.sleep(0.05)
'''

WATCHER = r'''
import json
import re
import rospy
from rosgraph_msgs.msg import Log
def show(m):
    if m.name != "/log_talker":
        return
    print("LOG " + json.dumps({"level": m.level, "name": m.name, "msg": m.msg, "file": m.file,
          "function": m.function, "line": m.line, "topics": sorted(m.topics),
          "stamp": m.header.stamp.to_sec()}), flush=True)
rospy.init_node("log_watcher")
rospy.Subscriber("/rosout", Log, show)
print("WATCHING", flush=True)
rospy.spin()
'''


@pytest.mark.smoke
def test_rosout_messages_reach_a_subscriber(minros_master: int, ros_home: Path, tmp_path: Path):
    env = ros_env(minros_master, ros_home)
    talker_py, watcher_py = tmp_path / "talker.py", tmp_path / "watcher.py"
    talker_py.write_text(TALKER)
    watcher_py.write_text(WATCHER)
    watcher = Proc([PYTHON, str(watcher_py)], env)
    talker = None
    try:
        watcher.read_until("WATCHING", 30)
        talker = Proc([PYTHON, str(talker_py)], env)
        out = watcher.read_until('"msg": "hello 3"', 30)
        logs = [json.loads(x[4:]) for x in out.splitlines() if x.startswith("LOG ")]
    finally:
        if talker is not None:
            talker_out = talker.stop()
        watcher.stop()
    infos = [m for m in logs if m["level"] == 2]
    warns = [m for m in logs if m["level"] == 4]
    assert infos and warns
    hello = next(m for m in infos if m["msg"] == "hello 3")
    lines = TALKER.splitlines()
    assert hello["name"] == "/log_talker"
    assert hello["file"] == "talker.py"
    assert hello["function"] == "<module>"
    assert lines[hello["line"] - 1].strip() == 'rospy.loginfo("hello %d", i)'
    assert {"/chatter", "/ignored", "/rosout"} <= set(hello["topics"])
    assert hello["stamp"] > 1e9
    warn = warns[0]
    assert warn["function"] == "Speaker.speak" and warn["msg"].startswith("warning ")
    assert lines[warn["line"] - 1].strip() == 'rospy.logwarn("warning %d", i)'
    assert not any(m["level"] == 1 for m in logs)  # DEBUG filtered before it is published
    # the console: INFO on stdout, WARN on stderr (both captured here), rospy's format
    assert any(line.startswith("[INFO] [") and line.endswith("]: hello 0")
               for line in talker_out.splitlines())
    assert any(line.startswith("[WARN] [") and line.endswith("]: warning 0")
               for line in talker_out.splitlines())
    # and the node's log file, as rospy writes it: $ROS_LOG_DIR/<node>.log
    log_file = (ros_home / "log" / "log_talker.log").read_text()
    assert re.search(r"^\[rosout\]\[INFO\] \d{4}-\d\d-\d\d [\d:,]+: hello 0$", log_file, re.M)
    assert re.search(r"^\[rosout\]\[WARNING\] .*: warning 0$", log_file, re.M)
    assert "debug is filtered" not in log_file
