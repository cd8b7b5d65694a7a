"""Test machinery for the ROS 1 <-> ROS 2 bridge (``minros ros2``): one network namespace
holding a master, the bridge, an rclpy agent and a minros ROS 1 agent, and the small ROS 1
programs (rospy under minros or Debian, roscpp built with g++) the tests run in it.

Everything that speaks DDS or reaches the master runs inside the namespace (``ip netns
exec``): the master's loopback is the namespace's own, so nothing outside can reach it and
nothing inside can reach eth0.
"""

from __future__ import annotations

import json
import os
import subprocess
import time
from pathlib import Path
from typing import Dict, List, Optional, Sequence

from ros2_support import AGENT, Agent, Netns, ros2_python, wait_for
from support import PYTHON, REFERENCE_PYTHON, Proc, reference_env

ROS1_AGENT = Path(__file__).with_name("ros1_bridge_agent.py")
BRIDGE_CYCLONE_AGENT = Path(__file__).with_name("bridge_cyclone_agent.py")
MASTER_PORT = 11311  # the namespace's own loopback: no other run shares it


class JsonAgent(Agent):
    """An agent whose stdout may carry a log line among its JSON answers (a ROS 1 node's
    console output): those are skipped."""

    def _read(self, timeout: float) -> dict:
        deadline = time.monotonic() + timeout
        while True:
            left = deadline - time.monotonic()
            if left <= 0:
                raise AssertionError(f"the agent did not answer within {timeout} s; stderr: "
                                     f"{self.stderr()}")
            try:
                line = self._lines.get(timeout=left)
            except Exception:  # queue.Empty
                continue
            if line is None:
                raise AssertionError(f"the agent exited ({self.proc.poll()}); stderr: "
                                     f"{self.stderr()}")
            if line.startswith("{"):
                return json.loads(line)


class World:
    """One namespace with a master on MASTER_PORT, and whatever a test starts in it."""

    def __init__(self, tmp: Path) -> None:
        self.tmp = tmp
        self.ns = Netns()
        self.procs: List[Proc] = []
        self.home = tmp / "ros_home"
        self.home.mkdir(exist_ok=True)
        self.master = self.start([PYTHON, "-m", "minros", "core", "-p", str(MASTER_PORT)],
                                 "master")
        self.master.read_until("started core service", 30)

    def env(self, extra: Optional[Dict[str, str]] = None) -> Dict[str, str]:
        env = {k: v for k, v in os.environ.items()
               if not k.startswith(("ROS_", "RMW_", "FASTDDS", "FASTRTPS")) and k != "PYTHONPATH"}
        env.update({"ROS_MASTER_URI": f"http://localhost:{MASTER_PORT}",
                    "ROS_HOSTNAME": "localhost", "ROS_HOME": str(self.home),
                    "ROS_LOG_DIR": str(self.home / "log"), "PYTHONUNBUFFERED": "1"})
        env.update(extra or {})
        return env

    def start(self, argv: Sequence[str], name: str, env: Optional[Dict[str, str]] = None,
              reference: bool = False, stdin=subprocess.DEVNULL) -> Proc:
        environment = self.env(env)
        if reference:
            environment = reference_env(environment)
        proc = Proc(self.ns.argv(list(argv)), environment, stdin=stdin)
        self.procs.append(proc)
        return proc

    def bridge(self, *args: str, distro: str = "jazzy") -> Proc:
        proc = self.start([PYTHON, "-m", "minros", "ros2", "--distro", distro, *args], "bridge")
        return proc

    def rclpy(self, distro: str, name: str = "rclpy_agent",
              env: Optional[Dict[str, str]] = None) -> Agent:
        agent = Agent(self.ns, ros2_python(distro), AGENT, name, self.tmp, env)
        self.agents.append(agent)
        return agent

    def ros1_agent(self, name: str = "ros1_agent") -> JsonAgent:
        agent = JsonAgent(self.ns, Path(PYTHON), ROS1_AGENT, name, self.tmp,
                          {k: v for k, v in self.env().items() if k.startswith("ROS_")})
        self.agents.append(agent)
        return agent

    @property
    def agents(self) -> list:
        if not hasattr(self, "_agents"):
            self._agents: list = []
        return self._agents

    def run_in(self, argv: Sequence[str], timeout: float = 30, reference: bool = False,
               env: Optional[Dict[str, str]] = None) -> subprocess.CompletedProcess:
        environment = self.env(env)
        if reference:
            environment = reference_env(environment)
        return subprocess.run(self.ns.argv(list(argv)), env=environment, capture_output=True,
                              text=True, timeout=timeout)

    def close(self) -> None:
        for agent in reversed(self.agents):
            try:
                agent.close()
            except Exception:  # noqa: BLE001 - the rest still closes
                pass
        for proc in reversed(self.procs):
            proc.stop()
        self.ns.delete()


def lines_of(proc: Proc, needle: str, count: int, timeout: float) -> List[str]:
    """Read ``proc``'s output until ``count`` lines contain ``needle``; those lines."""
    found: List[str] = []
    deadline = time.monotonic() + timeout
    while len(found) < count:
        left = deadline - time.monotonic()
        if left <= 0:
            raise AssertionError(f"{len(found)} of {count} lines with {needle!r} within "
                                 f"{timeout} s; the last: {found[-3:]}")
        text = proc.read_until(needle, left)
        found += [line for line in text.splitlines() if needle in line]
    return found


def drain(proc: Proc, seconds: float) -> str:
    """What ``proc`` writes within ``seconds`` (and what it wrote before, not yet read)."""
    import select

    assert proc.popen.stdout is not None
    fd = proc.popen.stdout.fileno()
    data = proc._pending
    proc._pending = b""
    deadline = time.monotonic() + seconds
    while True:
        left = deadline - time.monotonic()
        if left <= 0 or not select.select([fd], [], [], left)[0]:
            break
        chunk = os.read(fd, 65536)
        if not chunk:
            break
        data += chunk
    return data.decode("utf-8", "replace")


__all__ = ["BRIDGE_CYCLONE_AGENT", "JsonAgent", "drain", "MASTER_PORT", "World", "lines_of",
           "wait_for", "REFERENCE_PYTHON"]


# -- ROS 1 programs ---------------------------------------------------------------------------

#: a rospy talker (the same text under minros and Debian's rospy): "warm i" every 50 ms until
#: a line comes on stdin, then COUNT messages "msg i" at HZ, then "sent COUNT"
TALKER = r'''
import select
import sys
import rospy
from std_msgs.msg import String

topic, count, hz = sys.argv[1], int(sys.argv[2]), float(sys.argv[3])
pub = rospy.Publisher(topic, String, queue_size=1000)
rospy.init_node("talker", anonymous=True)
print("talker up", flush=True)
i = 0
while not rospy.is_shutdown():
    if select.select([sys.stdin], [], [], 0.05)[0]:
        sys.stdin.readline()
        break
    pub.publish(String("warm %d" % i))
    i += 1
rate = rospy.Rate(hz)
for i in range(count):
    pub.publish(String("msg %d" % i))
    rate.sleep()
print("sent %d" % count, flush=True)
rospy.spin()
'''

#: a rospy listener: prints "got <data>" for each message, "listener done N" after COUNT
#: messages starting with "msg "
LISTENER = r'''
import sys
import rospy
from std_msgs.msg import String

topic, count = sys.argv[1], int(sys.argv[2])
seen = []


def callback(m):
    print("got %s" % m.data, flush=True)
    if m.data.startswith("msg "):
        seen.append(m.data)
        if len(seen) >= count:
            rospy.signal_shutdown("done")


rospy.init_node("listener", anonymous=True)
rospy.Subscriber(topic, String, callback, queue_size=1000)
print("subscribed", flush=True)
rospy.spin()
print("listener done %d" % len(seen), flush=True)
'''

#: rospy services: SetBool answers success=data, "rospy set <data>"; Trigger "rospy triggered"
SERVER = r'''
import sys
import rospy
from std_srvs.srv import SetBool, SetBoolResponse, Trigger, TriggerResponse

rospy.init_node("ros1_server")
rospy.Service(sys.argv[1], SetBool, lambda r: SetBoolResponse(r.data, "rospy set %s" % r.data))
rospy.Service(sys.argv[2], Trigger, lambda r: TriggerResponse(True, "rospy triggered"))
print("serving", flush=True)
rospy.spin()
'''

#: a rospy client: waits for both services, calls SetBool(True), SetBool(False), Trigger
CLIENT = r'''
import sys
import rospy
from std_srvs.srv import SetBool, Trigger

rospy.init_node("ros1_client", anonymous=True)
rospy.wait_for_service(sys.argv[1], 20)
rospy.wait_for_service(sys.argv[2], 20)
setbool = rospy.ServiceProxy(sys.argv[1], SetBool)
for value in (True, False):
    r = setbool(value)
    print("setbool %s -> %s %s" % (value, r.success, r.message), flush=True)
r = rospy.ServiceProxy(sys.argv[2], Trigger)()
print("trigger -> %s %s" % (r.success, r.message), flush=True)
'''

#: a roscpp talker and listener with the same behaviour as TALKER and LISTENER
NODE_CPP = r'''
#include <ros/ros.h>
#include <std_msgs/String.h>
#include <sys/select.h>
#include <unistd.h>
#include <cstdio>
#include <cstdlib>
#include <string>

static int wanted = 0, seen = 0;

static void onString(const std_msgs::String::ConstPtr& m) {
  printf("got %s\n", m->data.c_str());
  fflush(stdout);
  if (m->data.compare(0, 4, "msg ") == 0 && ++seen >= wanted) ros::shutdown();
}

static bool lineOnStdin() {
  fd_set fds; FD_ZERO(&fds); FD_SET(0, &fds);
  struct timeval tv = {0, 50000};
  if (select(1, &fds, nullptr, nullptr, &tv) > 0) { char buf[64]; (void)!read(0, buf, sizeof buf); return true; }
  return false;
}

int main(int argc, char** argv) {
  std::string mode = argv[1];
  ros::init(argc, argv, mode, ros::init_options::AnonymousName);
  ros::NodeHandle nh;
  std::string topic = argv[2];
  int count = atoi(argv[3]);
  if (mode == "listener") {
    wanted = count;
    ros::Subscriber sub = nh.subscribe(topic, 1000, onString);
    printf("subscribed\n"); fflush(stdout);
    ros::spin();
    printf("listener done %d\n", seen); fflush(stdout);
    return 0;
  }
  double hz = atof(argv[4]);
  ros::Publisher pub = nh.advertise<std_msgs::String>(topic, 1000);
  printf("talker up\n"); fflush(stdout);
  for (int i = 0; ros::ok() && !lineOnStdin(); ++i) {
    std_msgs::String m; m.data = "warm " + std::to_string(i); pub.publish(m);
  }
  ros::Rate rate(hz);
  for (int i = 0; i < count && ros::ok(); ++i) {
    std_msgs::String m; m.data = "msg " + std::to_string(i); pub.publish(m); rate.sleep();
  }
  printf("sent %d\n", count); fflush(stdout);
  ros::spin();
  return 0;
}
'''
