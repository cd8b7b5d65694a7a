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


# the tools' internals real code calls (rostopic._get_topic_type to find an action's type,
# ROSTopicBandwidth in monitors, create_publisher, rosnode's descriptions and clean-up,
# rosservice_find, ...); run by both interpreters against the same graph, one JSON line
INTERNALS_SCRIPT = r'''
import contextlib, io, json, os, sys, tempfile, time
import rosgraph, rosnode, rosparam, rospy, rosservice, rostopic, yaml

def printed(fn, *args, **kwds):
    out = io.StringIO()
    with contextlib.redirect_stdout(out):
        fn(*args, **kwds)
    return out.getvalue()

out = {}
master = rosgraph.Master("/internals")
rostopic._check_master()
out["_get_topic_type"] = list(rostopic._get_topic_type("/chatter/data")[:2])
out["_master_get_topic_types"] = ["/chatter", "std_msgs/String"] in [
    list(x) for x in rostopic._master_get_topic_types(master)]
pubs, subs = rostopic.get_topic_list()
out["get_topic_list"] = [list(p) for p in pubs if p[0] == "/chatter"]
out["find_by_type"] = "/chatter" in rostopic.find_by_type("std_msgs/String")
uri = master.lookupNode("/chatter_pub")
out["get_api"] = [rostopic.get_api(master, "/chatter_pub") == uri,
                  rostopic.get_api(master, "/nobody")]
path = os.path.join(tempfile.mkdtemp(), "msgs.yaml")
with open(path, "w") as f:
    f.write("data: a\n---\ndata: b\n")
out["file_yaml_arg"] = list(rostopic.file_yaml_arg(path)())
from std_msgs.msg import Header, String
import genpy
out["value_transform"] = genpy.message.strify_message(
    rostopic.create_value_transform(True, False)(String("abc")))
out["field_filter"] = list(rostopic.create_field_filter(False, True)(Header()))
echo = rostopic.CallbackEcho("/chatter", None, count=2)
out["echo"] = printed(echo.callback, String("hi"), {"topic": "/chatter"})
out["echo_other_topic"] = printed(echo.callback, String("no"), {"topic": "/other"})
printed(echo.callback, String("two"), {"topic": "/chatter"})
out["echo_done"] = [echo.count, echo.done]
field = rostopic.CallbackEcho("/chatter/data", None)
out["echo_field"] = printed(field.callback, String("hi"), {"topic": "/chatter"})
plot = rostopic.CallbackEcho("/chatter", None, plot=True)
out["echo_plot"] = printed(plot.callback, String("hi"), {"topic": "/chatter"},
                           current_time=rospy.Time(5))
try:
    rostopic.create_publisher("/api_pub", "nope_msgs/Nope", True)
except rostopic.ROSTopicException as exc:
    out["create_publisher_error"] = str(exc)
pub, msg_class = rostopic.create_publisher("/api_pub", "std_msgs/String", True)
out["create_publisher"] = [pub.resolved_name, msg_class._type]
out["publish_message"] = printed(rostopic.publish_message, pub, msg_class,
                                 [{"data": "latched"}], once=True)
got = rospy.wait_for_message("/api_pub", String, timeout=10)
out["latched"] = got.data
try:
    rostopic.publish_message(pub, msg_class, [{"nope": 1}], once=True)
except rostopic.ROSTopicException as exc:
    out["publish_error"] = type(exc).__name__
try:
    rostopic.param_publish_once(pub, msg_class, "/no_such_param", False)
except rostopic.ROSTopicException as exc:
    out["param_publish_error"] = str(exc)
bw = rostopic.ROSTopicBandwidth(window_size=5)
sub = rospy.Subscriber("/chatter", rospy.AnyMsg, bw.callback)
deadline = time.time() + 10
while len(bw.sizes) < 7 and time.time() < deadline:
    time.sleep(0.05)
sub.unregister()
out["bw_sizes"] = bw.sizes
out["bw_text"] = printed(bw.print_bw).split("/s")[0].startswith("average: ")
out["node_info"] = rosnode.get_node_info_description("/chatter_pub")
out["listnodes"] = printed(rosnode.rosnode_listnodes, namespace="/chatter_pub")
out["listnodes_uri"] = printed(rosnode.rosnode_listnodes, namespace="/chatter_pub", list_uri=True) == uri + "\n"
state = master.getSystemState()
out["lookup_uri"] = rosnode.lookup_uri(master, state, "/chatter", uri) == "/chatter_pub (%s)" % uri
conn = rosnode.get_node_connection_info_description(uri, master)
out["connection_info"] = [conn.startswith("Pid: "), " * topic: /rosout\n" in conn]
out["machines"] = "localhost" in rosnode.get_machines_by_nodes()
out["nodes_by_machine"] = "/chatter_pub" in rosnode.get_nodes_by_machine("localhost")
try:
    rosnode.get_nodes_by_machine("no-such-host.invalid")
except rosnode.ROSNodeException as exc:
    out["machine_error"] = str(exc)
out["rosnode_info_quiet"] = printed(rosnode.rosnode_info, "/chatter_pub", quiet=True)
out["debugnode"] = rosnode.rosnode_debugnode is rosnode.rosnode_info
ghost = rosgraph.Master("/ghost")
ghost.registerPublisher("/ghost_topic", "std_msgs/String", "http://localhost:9/")
printed(rosnode.cleanup_master_blacklist, master, ["/ghost"])
out["cleanup_blacklist"] = "/ghost_topic" in [t for t, _ in master.getSystemState()[0]]
out["has_service_args"] = [rosservice.has_service_args("/chatter_pub/get_loggers"),
                           rosservice.has_service_args("/chatter_pub/set_logger_level")]
out["rosservice_find"] = [s for s in rosservice.rosservice_find("roscpp/GetLoggers")
                          if s.startswith("/chatter_pub")]
out["param_server"] = rosparam.get_param_server().getParam("/run_id") == master.getParam("/run_id")
out["load_str"] = rosparam.load_str("a: 1\n---\n_ns: sub\nb: rad(pi)\n", "x.yaml",
                                    default_namespace="/ns")
class Loader(yaml.SafeLoader):
    pass
Loader.add_constructor("!degrees", rosparam.construct_angle_degrees)
Loader.add_constructor("!radians", rosparam.construct_angle_radians)
Loader.add_constructor("tag:yaml.org,2002:binary", rosparam.construct_yaml_binary)
loaded = yaml.load("a: !degrees 90\nb: !radians pi/2\nc: !!binary YWJj\n", Loader=Loader)
out["angles"] = [loaded["a"], loaded["b"], loaded["c"].data.decode()]
out["print_params"] = printed(rosparam.print_params, {"a": {"b": 1}, "c": "x"}, "/ns")
out["names"] = [rosparam.ns_join("/a", "b"), rosparam.GLOBALNS, rosparam.NS, rostopic.NAME,
                rosnode.ID, rosservice.NAME, rostopic.SUBSCRIBER_TIMEOUT]
print(json.dumps(out, sort_keys=True))
'''


def test_tool_internals_answer_as_debians(chatter_graph) -> None:
    """The helpers inside rostopic, rosnode, rosparam and rosservice that code calls directly
    give Debian's answers on the same graph."""
    _port, env = chatter_graph
    ours = subprocess.run([PYTHON, "-c", INTERNALS_SCRIPT], env=env, capture_output=True,
                          text=True, timeout=90)
    assert ours.returncode == 0, ours.stderr
    result = json.loads(ours.stdout.strip().splitlines()[-1])
    assert result["_get_topic_type"] == ["std_msgs/String", "/chatter"]
    assert result["get_topic_list"] == [["/chatter", "std_msgs/String", ["/chatter_pub"]]]
    assert result["echo"] == 'data: "hi"\n---\n' and result["echo_other_topic"] == ""
    assert result["echo_done"] == [2, True]
    assert result["echo_plot"] == "%time,field.data\n5000000000,hi\n"
    assert result["latched"] == "latched"
    assert result["bw_sizes"] == [9] * 5  # window 5 of 4-byte length + "hello"
    assert result["cleanup_blacklist"] is False
    assert result["has_service_args"] == [False, True]
    assert result["angles"][2] == "abc"
    require_reference()
    theirs = subprocess.run([REFERENCE_PYTHON, "-c", INTERNALS_SCRIPT], env=reference_env(env),
                            capture_output=True, text=True, timeout=90)
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

    def left() -> list:
        return sorted({n for section in master.getSystemState("/test")[2] for _t, ns in section
                       for n in ns if n.startswith("/script_")})

    try:
        wait_until(lambda: not left(), timeout=20, what="the launched nodes unregistered")
    except AssertionError:
        raise AssertionError(f"still registered: {left()}; the script printed:\n{run.stdout}\n"
                             f"{run.stderr}") from None


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
