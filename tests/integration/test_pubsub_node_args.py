"""init_node and the command line: remapping, __name/__ns/__master/__hostname, _param:=, anonymous."""

from __future__ import annotations

import json
import xmlrpc.client
from pathlib import Path

import pytest

from support import PYTHON, Proc, ros_env

SCRIPT = r'''
import json, os, sys
import rospy
from std_msgs.msg import String
anonymous = os.environ.get("ANON") == "1"
pub = rospy.Publisher("foo", String, queue_size=1)  # created before init_node, renamed by it
rospy.init_node("plain", anonymous=anonymous)
params = {}
for key in ("rate", "x", "b", "s", "str"):
    if rospy.has_param("~" + key):
        value = rospy.get_param("~" + key)
        params[key] = [value, type(value).__name__]
print("RESULT " + json.dumps({
    "name": rospy.get_name(), "namespace": rospy.get_namespace(),
    "resolved": rospy.resolve_name("foo"), "private": rospy.resolve_name("~p"),
    "pub": pub.resolved_name, "myargv": rospy.myargv()[1:], "params": params,
    "uri": rospy.get_node_uri(), "pid": os.getpid(),
}), flush=True)
rospy.signal_shutdown("done")
'''


def _run(tmp_path: Path, port: int, home: Path, args, extra_env=None) -> dict:
    script = tmp_path / "args_node.py"
    script.write_text(SCRIPT)
    proc = Proc([PYTHON, str(script), *args], ros_env(port, home, extra_env))
    out = proc.read_until("RESULT ", 20)
    proc.stop()
    return json.loads(out.split("RESULT ", 1)[1].splitlines()[0])


def test_remapping_and_special_keys(tmp_path, minros_master, ros_home):
    got = _run(tmp_path, minros_master, ros_home, [
        "plain_arg", "foo:=bar", "__name:=renamed", "__ns:=/ns1", "_rate:=10", "_x:=1.5",
        "_b:=true", "_s:=[1, 2]", "_str:=hello", "__hostname:=127.0.0.1", "__log:=/tmp/x.log"])
    assert got["name"] == "/ns1/renamed"
    assert got["namespace"] == "/ns1/"
    assert got["resolved"] == "/ns1/bar" and got["pub"] == "/ns1/bar"
    assert got["private"] == "/ns1/renamed/p"
    assert got["myargv"] == ["plain_arg"]
    # _param:=value is YAML-typed and uploaded as a private parameter
    assert got["params"] == {"rate": [10, "int"], "x": [1.5, "float"], "b": [True, "bool"],
                             "s": [[1, 2], "list"], "str": ["hello", "str"]}
    assert got["uri"].startswith("http://127.0.0.1:")


def test_anonymous_name_and_ros_namespace(tmp_path, minros_master, ros_home):
    got = _run(tmp_path, minros_master, ros_home, [], {"ANON": "1", "ROS_NAMESPACE": "/robot"})
    prefix = f"/robot/plain_{got['pid']}_"
    assert got["name"].startswith(prefix) and got["name"][len(prefix):].isdigit()
    assert got["pub"] == "/robot/foo"


def test_master_argument_beats_environment(tmp_path, minros_master, ros_home):
    # ROS_MASTER_URI points nowhere; __master:= names the real one
    script_env = {"ROS_MASTER_URI": "http://localhost:1/"}
    got = _run(tmp_path, minros_master, ros_home,
               [f"__master:=http://localhost:{minros_master}/", "__name:=via_arg"], script_env)
    assert got["name"] == "/via_arg"


def test_init_node_rejects_namespaced_names(tmp_path, minros_master, ros_home):
    script = tmp_path / "bad.py"
    script.write_text("import rospy\n"
                      "try:\n    rospy.init_node('a/b')\nexcept ValueError as e:\n    print('ERR', e)\n")
    proc = Proc([PYTHON, str(script)], ros_env(minros_master, ros_home))
    out = proc.read_until("ERR", 10)
    proc.stop()
    assert "namespaces are not allowed in node names" in out


@pytest.mark.parametrize("signal_name", ["SIGINT", "SIGTERM"])
def test_signals_shut_down_cleanly(tmp_path, minros_master, ros_home, signal_name):
    import signal

    script = tmp_path / "spinner.py"
    script.write_text("import rospy\nfrom std_msgs.msg import String\n"
                      "rospy.init_node('spinner')\n"
                      "p = rospy.Publisher('/spun', String, queue_size=1)\n"
                      "rospy.on_shutdown(lambda: print('hook ran', flush=True))\n"
                      "print('spinning', flush=True)\nrospy.spin()\nprint('spin returned', flush=True)\n")
    proc = Proc([PYTHON, str(script)], ros_env(minros_master, ros_home))
    proc.read_until("spinning", 20)
    proc.popen.send_signal(getattr(signal, signal_name))
    assert proc.popen.wait(10) == 0
    out = proc.output()
    assert "hook ran" in out and "spin returned" in out and "Traceback" not in out
    master = xmlrpc.client.ServerProxy(f"http://127.0.0.1:{minros_master}/")
    assert master.lookupNode("/t", "/spinner")[0] == -1


def test_node_started_before_the_master_registers_when_it_comes(tmp_path, ros_home):
    from support import free_port, wait_for_master, wait_until

    port = free_port()
    script = tmp_path / "early.py"
    script.write_text("import rospy\nfrom std_msgs.msg import String\n"
                      "p = rospy.Publisher('/early', String, queue_size=1)\n"
                      "rospy.init_node('early')\nprint('registered', flush=True)\nrospy.spin()\n")
    node = Proc([PYTHON, str(script)], ros_env(port, ros_home))
    master = None
    try:
        out = node.read_until("Unable to immediately register with master", 20)
        assert "registered" not in out
        master = Proc([PYTHON, "-m", "minros.master", "-p", str(port)], ros_env(port, ros_home))
        wait_for_master(port)
        node.read_until("registered", 10)
        proxy = xmlrpc.client.ServerProxy(f"http://127.0.0.1:{port}/")
        wait_until(lambda: ["/early", ["/early"]] in proxy.getSystemState("/t")[2][0], 5,
                   what="/early registered")
    finally:
        node.stop()
        if master is not None:
            master.stop()
