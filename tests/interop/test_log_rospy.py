"""Logging compared with Debian's rospy: the same script prints the same console lines (stdout
and stderr apart) and publishes the same rosgraph_msgs/Log fields on /rosout."""

from __future__ import annotations

import json
import re
import subprocess
from pathlib import Path

import pytest

from support import PYTHON, REFERENCE_PYTHON, Proc, reference_env, require_reference, ros_env

pytestmark = pytest.mark.interop

SCRIPT = r'''
import logging
import sys
import rospy
from std_msgs.msg import String

rospy.init_node(sys.argv[1])
pub = rospy.Publisher("/chatter", String, queue_size=1)
if len(sys.argv) > 2:  # wait for the /rosout subscriber, so no record predates its connection
    import time
    try:
        from rospy.impl.rosout import _rosout_pub as rosout
    except ImportError:
        from minros.client.rosout_log import _rosout
        rosout = _rosout.publisher
    deadline = time.monotonic() + 20
    while rosout.get_num_connections() < 1 and time.monotonic() < deadline:
        time.sleep(0.01)

class Speaker:
    def speak(self):
        rospy.logwarn("in a method %s", "x")

for i in range(3):
    rospy.loginfo_once("once %d" % i)
    rospy.logwarn_throttle(100, "throttled %d" % i)
    rospy.logerr_throttle_identical(100, "identical")
rospy.loginfo("plain %s and %d", "args", 7)
rospy.logdebug("hidden at the default level")
Speaker().speak()
rospy.logerr("an error")
rospy.logfatal("fatal")
logging.getLogger("rosout").info("python logging")
rospy.loginfo("named logger", logger_name="child")
print("DONE", flush=True)
'''

FORMAT = "[${severity}] [${logger}] [${function}] [${line}] [${file}]: ${message}"


def run(python: str, script: Path, env: dict, name: str, *extra: str) -> subprocess.CompletedProcess:
    return subprocess.run([python, str(script), name, *extra], env=env, capture_output=True,
                          text=True, timeout=60)


@pytest.fixture
def script(tmp_path: Path) -> Path:
    require_reference()
    path = tmp_path / "logging_script.py"
    path.write_text(SCRIPT)
    return path


def test_console_lines_match_rospy(script, debian_rosmaster, ros_home):
    env = ros_env(debian_rosmaster, ros_home, {"ROSCONSOLE_FORMAT": FORMAT})
    ref = run(REFERENCE_PYTHON, script, reference_env(env), "ref_logger")
    ours = run(PYTHON, script, env, "our_logger")
    assert ref.returncode == 0, ref.stderr
    assert ours.returncode == 0, ours.stderr
    assert ref.stdout.splitlines()[-1] == "DONE"
    assert ours.stdout == ref.stdout
    assert ours.stderr == ref.stderr
    # the oracle said something worth comparing
    assert "[WARN] [rosout] [Speaker.speak]" in ref.stderr
    assert "[INFO] [rosout.child] [<module>]" in ref.stdout


def test_default_format_and_streams_match_rospy(script, debian_rosmaster, ros_home):
    env = ros_env(debian_rosmaster, ros_home)
    ref = run(REFERENCE_PYTHON, script, reference_env(env), "ref_logger")
    ours = run(PYTHON, script, env, "our_logger")

    def shape(text: str) -> list:
        return [re.sub(r"^\[(\w+)\] \[\d+\.\d{6}\]: ", r"[\1] [T]: ", line) for line in text.splitlines()]

    assert shape(ours.stdout) == shape(ref.stdout)
    assert shape(ours.stderr) == shape(ref.stderr)
    assert "[INFO] [T]: plain args and 7" in shape(ref.stdout)


WATCHER = r'''
import json
import rospy
from rosgraph_msgs.msg import Log
def show(m):
    if m.name in ("/ref_logger", "/our_logger"):
        print("LOG " + json.dumps([m.name, m.level, m.msg, m.file, m.function, m.line,
                                   sorted(m.topics)]), flush=True)
rospy.init_node("log_watcher")
rospy.Subscriber("/rosout", Log, show, queue_size=100)
print("WATCHING", flush=True)
rospy.spin()
'''


def test_rosout_records_match_rospy(script, debian_rosmaster, ros_home, tmp_path):
    env = ros_env(debian_rosmaster, ros_home)
    watcher_py = tmp_path / "watcher.py"
    watcher_py.write_text(WATCHER)
    watcher = Proc([PYTHON, str(watcher_py)], env)
    try:
        watcher.read_until("WATCHING", 30)
        # each node stays up (spinning) until its last record reached the watcher
        script.write_text(script.read_text().replace('print("DONE", flush=True)',
                                                     'print("DONE", flush=True)\nrospy.spin()'))
        out = ""
        for python, penv, name in ((REFERENCE_PYTHON, reference_env(env), "/ref_logger"),
                                   (PYTHON, env, "/our_logger")):
            node = Proc([python, str(script), name[1:], "wait"], penv)
            try:
                out += watcher.read_until(f'"{name}", 2, "named logger"', 30)
            finally:
                node.stop()
    finally:
        watcher.stop()
    records: dict = {"/ref_logger": [], "/our_logger": []}
    for line in out.splitlines():
        if line.startswith("LOG "):
            name, *fields = json.loads(line[4:])
            records[name].append(fields)
    assert len(records["/ref_logger"]) >= 9
    assert records["/our_logger"] == records["/ref_logger"]
