"""The Python APIs real code imports, on a live graph: a script that starts with
``import roslib; roslib.load_manifest(...)`` and uses rostopic.get_topic_class runs unmodified;
roslaunch starts a command-line tool as a node (``<node pkg="rostopic" type="rostopic">``); the
tools' Python APIs answer as Debian's do on the same graph."""

from __future__ import annotations

import json
import subprocess
from pathlib import Path
from xmlrpc.client import ServerProxy

import pytest

from support import (
    PYTHON,
    REFERENCE_PYTHON,
    Proc,
    reference_env,
    require_reference,
    ros_env,
    wait_until,
)

ROSLIB_SCRIPT = '''#!/usr/bin/env python
import roslib; roslib.load_manifest('rospy_tutorials')
import rospy
import rostopic

rospy.init_node('topic_probe', anonymous=True)
msg_class, real_topic, _ = rostopic.get_topic_class('/chatter', blocking=True)
msg = rospy.wait_for_message(real_topic, msg_class, timeout=rospy.Duration(10))
print(msg_class._type, real_topic, msg.data)
'''

LAUNCH = '''<launch>
  <node pkg="rostopic" type="rostopic" name="chatter_pub"
        args="pub -r 20 /chatter std_msgs/String 'data: hello'"/>
</launch>
'''

# run by both interpreters against the same graph; prints one JSON line
API_SCRIPT = r'''
import json, os, sys, tempfile
import rosgraph, rosnode, rosparam, rosservice, rostopic
import genpy

out = {}
out["topic_type"] = list(rostopic.get_topic_type("/chatter")[:2])
out["field_type"] = list(rostopic.get_topic_type("/chatter/data")[:2])
cls, real, fn = rostopic.get_topic_class("/chatter/data")
out["field_eval"] = fn(cls(data="x")) if fn else None
out["missing_topic"] = list(rostopic.get_topic_type("/nope"))
out["nodes"] = sorted(n for n in rosnode.get_node_names() if not n.startswith("/rosout"))
out["ping"] = rosnode.rosnode_ping("/chatter_pub", max_count=1)
try:
    rosparam.delete_param("/api_test")  # the other interpreter's run left it
except rosparam.RosParamException:
    pass
rosparam.upload_params("/api_test", {"a": 1, "b": {"c": "two"}})
out["param"] = rosparam.get_param("/api_test")
rosparam.set_param("/api_test/d", "[1, 2.5]")
out["param_d"] = rosparam.get_param("/api_test/d")
path = os.path.join(tempfile.mkdtemp(), "p.yaml")
rosparam.dump_params(path, "/api_test")
loaded = rosparam.load_file(path, default_namespace="/copy")
out["load_file"] = [[values, ns] for values, ns in loaded]
out["services"] = sorted(s for s in rosservice.get_service_list(node="/chatter_pub"))
out["service_type"] = rosservice.get_service_type("/chatter_pub/get_loggers")
out["service_class"] = rosservice.get_service_class_by_name("/chatter_pub/get_loggers")._type
try:
    rosservice.get_service_class_by_name("/nope")
except rosservice.ROSServiceException as exc:
    out["service_error"] = str(exc)
master = rosgraph.Master("/api_test")
out["caller_id"] = master.caller_id
out["lookup"] = master.lookupNode("/chatter_pub").startswith("http://")
try:
    master.getParam("/not_set")
except rosgraph.MasterError as exc:
    out["master_error"] = str(exc)
out["online"] = rosgraph.is_master_online()
print(json.dumps(out, sort_keys=True))
'''


@pytest.fixture
def chatter_graph(minros_core: int, ros_home: Path, tmp_path: Path):
    """A minros core with `rostopic pub` started by roslaunch as a node of package rostopic."""
    launch = tmp_path / "pub.launch"
    launch.write_text(LAUNCH)
    env = ros_env(minros_core, ros_home)
    proc = Proc([PYTHON, "-m", "minros", "launch", str(launch)], env)
    try:
        proc.read_until("process[chatter_pub-1]: started", timeout=30)
        master = ServerProxy(f"http://localhost:{minros_core}/")

        def publishing() -> bool:
            pubs = master.getSystemState("/test")[2][0]
            return any(t == "/chatter" and "/chatter_pub" in nodes for t, nodes in pubs)

        wait_until(publishing, timeout=30, what="/chatter_pub publishing /chatter")
        yield minros_core, env
    finally:
        proc.stop()


def test_roslib_script_runs_unmodified(chatter_graph, tmp_path: Path) -> None:
    _port, env = chatter_graph
    script = tmp_path / "probe.py"
    script.write_text(ROSLIB_SCRIPT)
    run = subprocess.run([PYTHON, str(script)], env=env, capture_output=True, text=True, timeout=60)
    assert run.returncode == 0, run.stderr
    assert run.stdout.split() == ["std_msgs/String", "/chatter", "hello"]


def test_tool_apis_answer_as_debians_on_the_same_graph(chatter_graph) -> None:
    _port, env = chatter_graph
    ours = subprocess.run([PYTHON, "-c", API_SCRIPT], env=env, capture_output=True, text=True,
                          timeout=60)
    assert ours.returncode == 0, ours.stderr
    result = json.loads(ours.stdout.strip().splitlines()[-1])
    assert result["topic_type"] == ["std_msgs/String", "/chatter"]
    assert result["field_type"] == ["std_msgs/String", "/chatter"]
    assert result["field_eval"] == "x"
    assert result["missing_topic"] == [None, None, None]
    assert result["nodes"] == ["/chatter_pub"]
    assert result["param"] == {"a": 1, "b": {"c": "two"}}
    assert result["param_d"] == [1, 2.5]
    assert result["service_type"] == "roscpp/GetLoggers"
    assert result["caller_id"] == "/api_test"
    require_reference()
    theirs = subprocess.run([REFERENCE_PYTHON, "-c", API_SCRIPT], env=reference_env(env),
                            capture_output=True, text=True, timeout=60)
    assert theirs.returncode == 0, theirs.stderr
    assert result == json.loads(theirs.stdout.strip().splitlines()[-1])


ROSLAUNCH_SCRIPT = r'''
import sys, time
import roslaunch, rosnode

uuid = roslaunch.rlutil.get_or_generate_uuid(None, False)
roslaunch.configure_logging(uuid)
parent = roslaunch.parent.ROSLaunchParent(uuid, [sys.argv[1]])
parent.start()
launch = roslaunch.scriptapi.ROSLaunch()
launch.start()
process = launch.launch(roslaunch.core.Node("rospy_tutorials", "listener", name="script_listener"))
deadline = time.time() + 20
while time.time() < deadline:
    nodes = rosnode.get_node_names()
    if "/script_talker" in nodes and "/script_listener" in nodes:
        break
    time.sleep(0.1)
print(sorted(n for n in nodes if n.startswith("/script_")), process.is_alive())
process.stop()
launch.stop()
parent.shutdown()
print(process.is_alive())
'''


def test_roslaunch_scripting_api(minros_core: int, ros_home: Path, tmp_path: Path) -> None:
    launch = tmp_path / "talker.launch"
    launch.write_text('<launch><node pkg="rospy_tutorials" type="talker" name="script_talker"/>'
                      '</launch>')
    env = ros_env(minros_core, ros_home)
    run = subprocess.run([PYTHON, "-c", ROSLAUNCH_SCRIPT, str(launch)], env=env,
                         capture_output=True, text=True, timeout=90)
    assert run.returncode == 0, run.stderr
    # the launcher's own lines (process[...] started, killing on exit) come in between
    lines = [line for line in run.stdout.splitlines() if line in (
        "['/script_listener', '/script_talker'] True", "False")]
    assert lines == ["['/script_listener', '/script_talker'] True", "False"], run.stdout
    master = ServerProxy(f"http://localhost:{minros_core}/")
    wait_until(lambda: not any(n.startswith("/script_") for section in
                               master.getSystemState("/test")[2] for _t, ns in section for n in ns),
               timeout=20, what="the launched nodes unregistered")


OBJECT_MODEL = r'''
import time, rospy
from std_msgs.msg import String
rospy.init_node("model", anonymous=False)
pub = rospy.Publisher("/model_topic", String, queue_size=1)
sub = rospy.Subscriber("/model_topic", String, lambda m: None)
deadline = time.time() + 20
while time.time() < deadline and not (pub.get_num_connections() and sub.get_num_connections()):
    time.sleep(0.05)
conn = sub.impl.connections[0]
print(pub.impl.has_connection("/model"), pub.impl.has_connection("/other"), conn.callerid_pub,
      sub.impl.has_connection(conn.endpoint_id), len(sub.impl.connections))
'''


def test_rospy_object_model_read_by_libraries(minros_core: int, ros_home: Path) -> None:
    """actionlib's client reads pub.impl.has_connection(callerid) and walks sub.impl.connections
    for callerid_pub: both mean what they mean in rospy (checked with Debian's rospy too)."""
    env = ros_env(minros_core, ros_home)
    ours = subprocess.run([PYTHON, "-c", OBJECT_MODEL], env=env, capture_output=True, text=True,
                          timeout=60)
    assert ours.returncode == 0, ours.stderr
    assert ours.stdout.split() == ["True", "False", "/model", "True", "1"]
    require_reference()
    theirs = subprocess.run([REFERENCE_PYTHON, "-c", OBJECT_MODEL], env=reference_env(env),
                            capture_output=True, text=True, timeout=60)
    assert theirs.returncode == 0, theirs.stderr
    assert theirs.stdout.split() == ours.stdout.split()
