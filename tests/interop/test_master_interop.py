"""Debian's ROS 1 (rospy, roscpp and the command-line tools) against minros's master/core."""

from __future__ import annotations

import subprocess
import textwrap
import uuid
import xmlrpc.client
from pathlib import Path

import pytest

from support import (
    Proc,
    build_roscpp,
    free_port,
    reference_env,
    require_reference,
    ros_env,
    wait_until,
)

pytestmark = pytest.mark.interop

TALKER = """
import sys, rospy
from std_msgs.msg import String
rospy.init_node(sys.argv[2])
pub = rospy.Publisher(sys.argv[1], String, queue_size=10)
rate = rospy.Rate(20)
i = 0
while not rospy.is_shutdown():
    pub.publish(String('hello %d' % i))
    rospy.loginfo('said-%s %d', sys.argv[2], i)
    i += 1
    rate.sleep()
"""

LISTENER = """
import sys, rospy
from std_msgs.msg import String
rospy.init_node(sys.argv[2])
def heard(msg):
    print('heard: ' + msg.data, flush=True)
rospy.Subscriber(sys.argv[1], String, heard)
rospy.spin()
"""

SERVER = """
import sys, rospy
from std_srvs.srv import SetBool, SetBoolResponse
rospy.init_node(sys.argv[2])
rospy.Service(sys.argv[1], SetBool, lambda req: SetBoolResponse(True, 'got %s' % req.data))
print('ready', flush=True)
rospy.spin()
"""

ROSCPP = r"""
#include <ros/ros.h>
#include <std_msgs/String.h>
#include <string>
#include <iostream>
void heard(const std_msgs::String::ConstPtr& msg) { std::cout << "heard: " << msg->data << std::endl; }
int main(int argc, char** argv) {
  std::string mode = argv[1], topic = argv[2];
  ros::init(argc, argv, (mode == "talk" ? "cpp_talker" : "cpp_" + mode), ros::init_options::AnonymousName);
  ros::NodeHandle n;
  if (mode == "talk") {
    ros::Publisher pub = n.advertise<std_msgs::String>(topic, 10);
    ros::Rate rate(20);
    for (int i = 0; ros::ok(); ++i) {
      std_msgs::String msg; msg.data = "cpp " + std::to_string(i);
      pub.publish(msg); ros::spinOnce(); rate.sleep();
    }
  } else if (mode == "param") {
    std::string last = "<none>";
    ros::Rate rate(50);
    while (ros::ok()) {
      std::string value;
      if (!ros::param::getCached(topic, value)) value = "unset";
      if (value != last) { std::cout << "value: " << value << std::endl; last = value; }
      rate.sleep();
    }
  } else {
    ros::Subscriber sub = n.subscribe(topic, 10, heard);
    ros::spin();
  }
  return 0;
}
"""


def unique(prefix: str) -> str:
    return f"{prefix}_{uuid.uuid4().hex[:8]}"


class Ros:
    """Runs Debian's ROS programs against a master on ``port``."""

    def __init__(self, port: int, home: Path, tmp: Path) -> None:
        require_reference()
        self.port = port
        self.env = reference_env(ros_env(port, home))
        self.tmp = tmp
        self.procs = []

    def script(self, source: str, *args: str) -> Proc:
        path = self.tmp / f"{uuid.uuid4().hex}.py"
        path.write_text(textwrap.dedent(source))
        proc = Proc(["/usr/bin/python3", str(path), *args], self.env)
        self.procs.append(proc)
        return proc

    def start(self, *argv: str) -> Proc:
        proc = Proc(list(argv), self.env)
        self.procs.append(proc)
        return proc

    def run(self, *argv: str, input: str | None = None, timeout: float = 20) -> str:
        done = subprocess.run(list(argv), env=self.env, input=input, capture_output=True, text=True,
                              timeout=timeout)
        assert done.returncode == 0, f"{argv} failed ({done.returncode}):\n{done.stdout}{done.stderr}"
        return done.stdout

    def master(self):
        return xmlrpc.client.ServerProxy(f"http://127.0.0.1:{self.port}/")

    def close(self) -> None:
        # Short steps: Debian's rospy sometimes hangs in its own shutdown (with rosmaster too);
        # these are only test drivers, so do not wait 10 s for each.
        for proc in self.procs:
            proc.stop(timeout=1.0)

    def wait_subscribed(self, topic: str) -> None:
        def subscribed() -> bool:
            return any(entry[0] == topic for entry in self.master().getSystemState("/t")[2][1])
        wait_until(subscribed, timeout=20, what=f"a subscriber of {topic}")


@pytest.fixture
def ros_core(minros_core, ros_home, tmp_path):
    ros = Ros(minros_core, ros_home, tmp_path)
    yield ros
    ros.close()


@pytest.fixture(params=["minros_core", "minros_master"])
def ros_any(request, ros_home, tmp_path):
    ros = Ros(request.getfixturevalue(request.param), ros_home, tmp_path)
    yield ros
    ros.close()


def test_rospy_talker_listener(ros_any):
    topic = "/" + unique("chatter")
    # listener first, so that it learns of the talker through the master's publisherUpdate
    listener = ros_any.script(LISTENER, topic, unique("listener"))
    ros_any.wait_subscribed(topic)
    ros_any.script(TALKER, topic, unique("talker"))
    listener.read_until("heard: hello", timeout=20)


def test_rosout_aggregates_and_logs(ros_core, ros_home):
    name = unique("talker")
    ros_core.script(TALKER, "/" + unique("chatter"), name)
    echo = ros_core.start("/usr/bin/rostopic", "echo", "/rosout_agg")
    echo.read_until(f"said-{name}", timeout=20)
    run_id = ros_core.master().getParam("/t", "/run_id")[2]
    log = ros_home / "log" / run_id / "rosout.log"

    def logged() -> bool:
        return log.exists() and f"said-{name}" in log.read_text()

    wait_until(logged, timeout=10, what="the talker's log line in rosout.log")
    line = next(line for line in log.read_text().splitlines() if f"said-{name}" in line)
    assert f" INFO /{name} [" in line and "[topics: " in line


def test_rostopic(ros_core):
    topic = "/" + unique("chatter")
    name = unique("talker")
    ros_core.script(TALKER, topic, name)
    wait_until(lambda: topic in ros_core.run("/usr/bin/rostopic", "list"), 15, what="topic listed")
    listed = ros_core.run("/usr/bin/rostopic", "list")
    assert "/rosout\n" in listed and "/rosout_agg\n" in listed
    info = ros_core.run("/usr/bin/rostopic", "info", topic)
    assert "Type: std_msgs/String" in info and f"/{name}" in info
    echoed = ros_core.run("/usr/bin/rostopic", "echo", "-n", "1", topic)
    assert 'data: "hello' in echoed
    hz = ros_core.start("/usr/bin/rostopic", "hz", topic)
    hz.read_until("average rate", timeout=15)


def test_rosnode(ros_core):
    name = unique("talker")
    ros_core.script(TALKER, "/" + unique("chatter"), name)
    wait_until(lambda: f"/{name}" in ros_core.run("/usr/bin/rosnode", "list"), 15, what="node")
    assert "/rosout" in ros_core.run("/usr/bin/rosnode", "list").split()
    info = ros_core.run("/usr/bin/rosnode", "info", f"/{name}")
    assert "Publications:" in info and "/rosout [rosgraph_msgs/Log]" in info
    assert "reply from" in ros_core.run("/usr/bin/rosnode", "ping", "-c", "1", f"/{name}")
    # a node that died without unregistering: cleanup removes it
    dead = f"http://127.0.0.1:{free_port()}/"
    master = ros_core.master()
    assert master.registerPublisher("/ghost", "/ghost_topic", "std_msgs/String", dead)[0] == 1
    ros_core.run("/usr/bin/rosnode", "cleanup", input="y\n")
    assert master.lookupNode("/t", "/ghost")[0] == -1
    assert master.lookupNode("/t", f"/{name}")[0] == 1


def test_rosparam(ros_core, tmp_path):
    ns = "/" + unique("params")
    ros_core.run("/usr/bin/rosparam", "set", f"{ns}/a", "1")
    ros_core.run("/usr/bin/rosparam", "set", f"{ns}/b", "{x: 2.5, y: [1, two]}")
    assert ros_core.run("/usr/bin/rosparam", "get", f"{ns}/a").strip() == "1"
    assert "x: 2.5" in ros_core.run("/usr/bin/rosparam", "get", f"{ns}/b")
    listed = ros_core.run("/usr/bin/rosparam", "list").split()
    assert f"{ns}/a" in listed and f"{ns}/b/x" in listed and "/run_id" in listed
    dump = tmp_path / "dump.yaml"
    ros_core.run("/usr/bin/rosparam", "dump", str(dump), ns)
    assert "y:" in dump.read_text()
    ros_core.run("/usr/bin/rosparam", "load", str(dump), ns + "_copy")
    assert ros_core.master().getParam("/t", f"{ns}_copy/b/y")[2] == [1, "two"]
    ros_core.run("/usr/bin/rosparam", "delete", f"{ns}/a")
    assert ros_core.master().hasParam("/t", f"{ns}/a")[2] is False
    assert ros_core.master().getParam("/t", "/rosdistro")[2].endswith("\n")


def test_rosservice(ros_core):
    service = "/" + unique("set_bool")
    server = ros_core.script(SERVER, service, unique("server"))
    server.read_until("ready", timeout=20)
    assert service in ros_core.run("/usr/bin/rosservice", "list").split()
    out = ros_core.run("/usr/bin/rosservice", "call", service, "data: true")
    assert "success: True" in out and 'message: "got True"' in out


@pytest.fixture(scope="session")
def roscpp_binary(tmp_path_factory):
    return build_roscpp(ROSCPP, "chat", tmp_path_factory.mktemp("roscpp"), ("roscpp", "std_msgs"))


@pytest.mark.timeout(300)
def test_roscpp_talker_listener(roscpp_binary, ros_core):
    topic = "/" + unique("cpp_chatter")
    listener = ros_core.start(str(roscpp_binary), "listen", topic)
    ros_core.wait_subscribed(topic)  # the talker then reaches it through publisherUpdate
    ros_core.start(str(roscpp_binary), "talk", topic)
    listener.read_until("heard: cpp", timeout=20)
    # roscpp talker to rospy listener through the same master
    rospy_listener = ros_core.script(LISTENER, topic, unique("listener"))
    rospy_listener.read_until("heard: cpp", timeout=20)


CACHED = """
import sys, time, rospy
rospy.init_node(sys.argv[2])
last = None
deadline = time.time() + 30
while not rospy.is_shutdown() and time.time() < deadline:
    value = rospy.get_param_cached(sys.argv[1], 'unset')
    if value != last:
        print('value: %s' % (value,), flush=True)
        last = value
    time.sleep(0.02)
"""

SPINNER = """
import sys, rospy
rospy.init_node(sys.argv[1])
rospy.Subscriber('/' + sys.argv[1] + '_topic', rospy.AnyMsg, lambda m: None)
print('up', flush=True)
rospy.spin()
print('spin returned', flush=True)
"""


@pytest.mark.smoke
def test_rospy_param_cache_follows_param_updates(ros_core):
    key = "/" + unique("cached")
    master = ros_core.master()
    master.setParam("/t", key, 1)
    node = ros_core.script(CACHED, key, unique("cacher"))
    node.read_until("value: 1", timeout=20)
    master.setParam("/t", key, 2)  # reaches the node as paramUpdate, not by polling the master
    node.read_until("value: 2", timeout=10)
    master.setParam("/t", key, {"a": 3})
    node.read_until("value: {'a': 3}", timeout=10)
    master.deleteParam("/t", key)
    node.read_until("value: unset", timeout=10)


def test_same_name_node_replaces_the_old_one(ros_core):
    name = unique("twin")
    first = ros_core.script(SPINNER, name)
    first.read_until("up", timeout=20)
    old_uri = ros_core.master().lookupNode("/t", f"/{name}")[2]
    second = ros_core.script(SPINNER, name)
    second.read_until("up", timeout=20)
    # the master told the first one to shut down; rospy's spin() then returns
    first.read_until("spin returned", timeout=15)
    assert first.popen.wait(10) == 0
    new_uri = ros_core.master().lookupNode("/t", f"/{name}")[2]
    assert new_uri != old_uri and second.alive()


@pytest.mark.timeout(300)
def test_roscpp_param_cache_follows_param_updates(roscpp_binary, ros_core):
    key = "/" + unique("cpp_cached")
    master = ros_core.master()
    master.setParam("/t", key, "one")
    node = ros_core.start(str(roscpp_binary), "param", key)
    node.read_until("value: one", timeout=20)
    master.setParam("/t", key, "two")
    node.read_until("value: two", timeout=10)
    master.deleteParam("/t", key)
    node.read_until("value: unset", timeout=10)
