"""``minros zenoh`` across hosts: two network namespaces joined by a veth pair
(tests/interop/test_two_hosts.py's machinery, as root), each with its own master on port 11311
and every ROS socket on its own loopback (ROS_HOSTNAME=localhost), so the only thing the hosts
share is the Zenoh endpoint bridge a listens on (the test checks that a's master cannot be
reached from b). Debian's rospy talks and serves on one side and listens and calls on the
other; either bridge or master is killed and restarted, and the graph recovers within the
beacon timeout.
"""

from __future__ import annotations

import time
from typing import Dict

import pytest
from test_two_hosts import TwoHosts, hosts  # noqa: F401  (the fixture)

from support import PYTHON, REFERENCE_PYTHON
from zenoh_support import LISTENER, SETBOOL_SERVER, TALKER, require_zenoh

pytestmark = [pytest.mark.interop, pytest.mark.timeout(180)]

MASTER_PORT = 11311
ZENOH_PORT = 7447


class Sites:
    """A master and a bridge in each namespace; bridge a listens, bridge b connects."""

    def __init__(self, hosts: TwoHosts) -> None:  # noqa: F811
        self.hosts = hosts
        self.endpoint = f"tcp/{hosts.ip['a']}:{ZENOH_PORT}"
        self.masters: Dict[str, object] = {}
        self.bridges: Dict[str, object] = {}
        for side in ("a", "b"):
            self.start_master(side)
        self.start_bridge("a")
        self.start_bridge("b")

    def env(self, side: str, reference: bool = False) -> Dict[str, str]:
        return self.hosts.env(f"http://localhost:{MASTER_PORT}/", {"ROS_HOSTNAME": "localhost"},
                              reference=reference)

    def start_master(self, side: str):
        proc = self.hosts.run(side, [PYTHON, "-m", "minros", "core", "-p", str(MASTER_PORT)],
                              self.env(side))
        probe = ("import sys, xmlrpc.client; sys.exit(xmlrpc.client.ServerProxy("
                 f"'http://localhost:{MASTER_PORT}/').getPid('/t')[0] != 1)")
        deadline = time.monotonic() + 20
        while self.hosts.call(side, [PYTHON, "-c", probe], {}, timeout=10).returncode != 0:
            assert time.monotonic() < deadline, f"the master on {side} did not come up"
            time.sleep(0.2)
        self.masters[side] = proc
        return proc

    def start_bridge(self, side: str):
        where = ["--listen", self.endpoint] if side == "a" else ["--connect", self.endpoint]
        proc = self.hosts.run(side, [PYTHON, "-m", "minros", "zenoh", "--no-multicast-scouting",
                                     *where], self.env(side))
        proc.read_until("minros zenoh: bridging the master", 20)
        self.bridges[side] = proc
        return proc

    def kill(self, proc) -> None:
        import os
        import signal

        os.killpg(proc.popen.pid, signal.SIGKILL)
        proc.popen.wait(10)


@pytest.fixture
def sites(hosts):  # noqa: F811
    require_zenoh()
    return Sites(hosts)


def test_only_zenoh_joins_the_hosts_and_debian_nodes_talk_and_call_through_it(sites):
    net = sites.hosts
    # no route between the ROS ports: b cannot reach a's master, which listens on a's loopback
    probe = net.call("b", [PYTHON, "-c", "import socket; socket.create_connection("
                             f"('{net.ip['a']}', {MASTER_PORT}), timeout=3)"], {})
    assert probe.returncode != 0 and "ConnectionRefusedError" in probe.stderr
    # Debian's rospy on both sides: a talker and a service on a, a listener and a client on b
    net.run("a", [REFERENCE_PYTHON, "-c", TALKER, "chatter"], sites.env("a", reference=True))
    net.run("a", [REFERENCE_PYTHON, "-c", SETBOOL_SERVER, "set_flag"],
              sites.env("a", reference=True)).read_until("serving", 20)
    listener = net.run("b", [REFERENCE_PYTHON, "-c", LISTENER, "chatter"],
                         sites.env("b", reference=True))
    listener.read_until("I heard hello", 30)
    sites.bridges["b"].read_until("bridging /set_flag (std_srvs/SetBool) service Zenoh -> ROS", 20)
    env_b = sites.env("b", reference=True)
    ok = net.call("b", ["/usr/bin/rosservice", "call", "/set_flag", "data: true"], env_b)
    assert "success: True" in ok.stdout, ok.stdout + ok.stderr
    refused = net.call("b", ["/usr/bin/rosservice", "call", "/set_flag", "data: false"], env_b)
    assert "false is refused" in refused.stderr + refused.stdout
    # and the other way: a minros talker on b, Debian's listener on a
    net.run("b", [PYTHON, "-c", TALKER, "chatter_back"], sites.env("b"))
    back = net.run("a", [REFERENCE_PYTHON, "-c", LISTENER, "chatter_back"],
                     sites.env("a", reference=True))
    back.read_until("I heard hello", 30)
    info = net.call("b", ["/usr/bin/rostopic", "info", "/chatter"], env_b).stdout
    assert "Type: std_msgs/String" in info and "/minros_zenoh" in info


def _heard_again(listener, within: float) -> float:
    """Seconds until the listener hears a message printed after now."""
    start = time.monotonic()
    # drop what is buffered, then wait for a fresh line
    try:
        while True:
            listener.read_until("I heard", 0.05)
    except AssertionError:
        pass
    listener.read_until("I heard", within)
    return time.monotonic() - start


def test_restart_of_either_bridge_or_master_recovers_within_the_beacon_timeout(sites):
    net = sites.hosts
    net.run("a", [PYTHON, "-c", TALKER, "chatter", "20"], sites.env("a"))
    listener = net.run("b", [PYTHON, "-c", LISTENER, "chatter"], sites.env("b"))
    listener.read_until("I heard hello", 30)
    for side in ("a", "b"):  # a bridge killed and started again
        sites.kill(sites.bridges[side])
        time.sleep(1.0)
        sites.start_bridge(side)
        took = _heard_again(listener, 10)
        assert took <= 3.5, f"bridge {side} restarted: heard again after {took:.2f} s"
    for side in ("a", "b"):  # a master killed and started again: minros nodes re-register
        sites.kill(sites.masters[side])
        time.sleep(1.0)
        sites.start_master(side)
        took = _heard_again(listener, 15)
        # nodes notice the new master within a second (minros probes it each second), then
        # the bridge's next reading of the graph and one beacon
        assert took <= 3.5 + 1.0, f"master {side} restarted: heard again after {took:.2f} s"
    for side, bridge in sites.bridges.items():
        text = bridge.stop()
        assert "Traceback" not in text, f"bridge {side}:\n{text}"
