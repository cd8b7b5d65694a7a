"""Test helpers for ``minros zenoh``: two masters joined by two bridges, a Zenoh session of the
test's own (a plain Zenoh application, or zenoh-bridge-ros1 as its source and tests show it on
the wire), and the ROS scripts both sides run.

The emulated zenoh-bridge-ros1 does what zenoh-plugin-ros1 (HEAD 16ebad5) does on the wire:
empty beacons every second on ``ros1_discovery_info/*/<class>/<hex>/<md5>/*/<topic>``
(best effort, dropped under congestion), messages put as bare bodies on
``<hex>/<md5>/*/<topic>``, services as queryables that reply the response body, or the error
text as an ordinary reply (``abstract_bridge.rs`` ``reply_to_query``).
"""

from __future__ import annotations

import json
import threading
import time
from pathlib import Path
from typing import Dict, List, Optional

import pytest

from support import IN_CI, PYTHON, Proc, free_port, ros_env, wait_for_master

STRING_MD5 = "992ce8a1687cec8c8bd883ec73ca41d1"
SETBOOL_MD5 = "09fb03525b03e7ea1fd3992bafd87e16"

TALKER = r'''
import sys, rospy
from std_msgs.msg import String
rospy.init_node("talker", anonymous=True)
pub = rospy.Publisher(sys.argv[1], String, queue_size=10)
rate = rospy.Rate(float(sys.argv[2]) if len(sys.argv) > 2 else 20)
i = 0
while not rospy.is_shutdown():
    pub.publish(String("hello %d" % i))
    i += 1
    rate.sleep()
'''

LISTENER = r'''
import sys, rospy
from std_msgs.msg import String
rospy.init_node("listener", anonymous=True)
rospy.Subscriber(sys.argv[1], String, lambda m: print("I heard", m.data, flush=True))
print("listening", flush=True)
rospy.spin()
'''

SETBOOL_SERVER = r'''
import sys, rospy
from std_srvs.srv import SetBool, SetBoolResponse
rospy.init_node("setbool_server", anonymous=True)
def handle(req):
    if not req.data:
        raise rospy.ServiceException("false is refused")
    return SetBoolResponse(True, "set by " + rospy.get_name())
rospy.Service(sys.argv[1], SetBool, handle)
print("serving", flush=True)
rospy.spin()
'''


def require_zenoh() -> None:
    """The extra is part of the test install: missing, it fails in CI and skips elsewhere."""
    from minros import zenoh as extra

    if extra.available():
        return
    if IN_CI:
        pytest.fail("eclipse-zenoh is not installed (pip install -e '.[test]' installs it)")
    pytest.skip("eclipse-zenoh is not installed: pip install minros[zenoh]")


class Site:
    """One master and its bridge (and whatever the test starts there)."""

    def __init__(self, name: str, home: Path, bridge_args: List[str]) -> None:
        self.name = name
        self.port = free_port()
        self.home = home / name
        (self.home / "log").mkdir(parents=True)
        self.env = ros_env(self.port, self.home)
        self.procs: List[Proc] = []
        self.master = self.start([PYTHON, "-m", "minros.master", "-p", str(self.port)])
        wait_for_master(self.port)
        self.bridge_args = bridge_args
        self.bridge: Optional[Proc] = None
        self.banner = ""
        self.start_bridge()

    def start(self, argv: List[str], env: Optional[Dict[str, str]] = None) -> Proc:
        proc = Proc(argv, env or self.env)
        self.procs.append(proc)
        return proc

    def start_bridge(self) -> Proc:
        self.bridge = self.start([PYTHON, "-m", "minros", "zenoh", "--no-multicast-scouting",
                                  *self.bridge_args])
        self.banner = self.bridge.read_until("minros zenoh: bridging the master", 20)
        return self.bridge

    def python(self, code: str, *args: str) -> Proc:
        return self.start([PYTHON, "-c", code, *args])

    def tool(self, *args: str, timeout: float = 30):
        import subprocess

        return subprocess.run([PYTHON, "-m", "minros", *args], env=self.env, capture_output=True,
                              text=True, timeout=timeout)

    def close(self) -> None:
        for proc in reversed(self.procs):
            proc.stop()


class Pair:
    """Sites ``a`` (its bridge listens on a loopback port) and ``b`` (its bridge connects)."""

    def __init__(self, home: Path, extra_args: Optional[List[str]] = None) -> None:
        self.endpoint = f"tcp/127.0.0.1:{free_port()}"
        extra = list(extra_args or [])
        self.a = Site("a", home, ["--listen", self.endpoint, *extra])
        try:
            self.b = Site("b", home, ["--connect", self.endpoint, *extra])
        except BaseException:
            self.a.close()
            raise

    def close(self) -> None:
        self.b.close()
        self.a.close()


def zenoh_session(connect: str):
    """A Zenoh peer of the test's own, connected to ``connect``, no multicast."""
    import zenoh

    config = zenoh.Config()
    config.insert_json5("scouting/multicast/enabled", "false")
    config.insert_json5("connect/endpoints", json.dumps([connect]))
    return zenoh.open(config)


class EmulatedBridge:
    """zenoh-bridge-ros1 as its source shows it on the wire: beacons, bare bodies, queryables
    that reply error texts as ordinary payloads."""

    def __init__(self, session) -> None:
        import zenoh

        self.zenoh = zenoh
        self.session = session
        self.beacons: Dict[str, object] = {}
        self._stop = threading.Event()
        self._thread = threading.Thread(target=self._beacon_loop, daemon=True)
        self._thread.start()
        self.kept: List[object] = []

    def declare(self, key: str) -> None:
        z = self.zenoh
        self.beacons[key] = self.session.declare_publisher(
            key, reliability=z.Reliability.BEST_EFFORT, congestion_control=z.CongestionControl.DROP,
            priority=z.Priority.BACKGROUND, allowed_destination=z.Locality.REMOTE)
        self.beacons[key].put(b"")

    def undeclare(self, key: str) -> None:
        self.beacons.pop(key).undeclare()

    def _beacon_loop(self) -> None:
        while not self._stop.wait(1.0):
            for publisher in list(self.beacons.values()):
                publisher.put(b"")

    def publisher(self, key: str):
        z = self.zenoh
        pub = self.session.declare_publisher(key, reliability=z.Reliability.RELIABLE,
                                             congestion_control=z.CongestionControl.BLOCK,
                                             allowed_destination=z.Locality.REMOTE)
        self.kept.append(pub)
        return pub

    def queryable(self, key: str, answer) -> None:
        def on_query(query):
            query.reply(query.key_expr, answer(query.payload.to_bytes() if query.payload else b""))
        self.kept.append(self.session.declare_queryable(
            key, on_query, allowed_origin=self.zenoh.Locality.REMOTE))

    def close(self) -> None:
        self._stop.set()
        self._thread.join(3)
        for publisher in self.beacons.values():
            publisher.undeclare()
        self.beacons.clear()


def count_lines(text: str, needle: str) -> int:
    return sum(1 for line in text.splitlines() if needle in line)


def wait_gone(predicate, timeout: float) -> float:
    """Seconds until ``predicate()`` is false (AssertionError after ``timeout``)."""
    start = time.monotonic()
    while predicate():
        if time.monotonic() - start > timeout:
            raise AssertionError(f"still there after {timeout}s")
        time.sleep(0.05)
    return time.monotonic() - start
