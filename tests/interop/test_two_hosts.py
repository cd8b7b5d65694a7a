"""Two hosts on one machine: network namespaces joined by a veth pair (as root; CI runs as root,
elsewhere these tests skip with the reason).

``hosta`` (10.x.y.1) runs the master, ``hostb`` (10.x.y.2) runs nodes, each namespace with its
own /etc/hosts (``/etc/netns/<ns>/hosts``, which ``ip netns exec`` mounts), so ROS_HOSTNAME and
ROS_IP are set as users set them. Debian's rospy runs on one side and minros on the other, in
both directions; the classic mistakes (a host name the other side cannot resolve, a wrong
ROS_IP) show as ROS shows them; and ROS_ALLOWED_HOSTS refuses the peer in the other namespace
while admitting its own.
"""

from __future__ import annotations

import os
import shutil
import subprocess
import time
import uuid
from pathlib import Path
from typing import Dict, List

import pytest

from support import (
    IN_CI,
    PYTHON,
    REFERENCE_PYTHON,
    Proc,
    free_port,
    reference_env,
    require_reference,
    ros_env,
    wait_until,
)

pytestmark = [pytest.mark.interop, pytest.mark.timeout(120)]

TALKER = r'''
import rospy
from std_msgs.msg import String
rospy.init_node("talker")
pub = rospy.Publisher("chatter", String, queue_size=10)
rate = rospy.Rate(20)
i = 0
while not rospy.is_shutdown():
    pub.publish(String("hello %d" % i))
    i += 1
    rate.sleep()
'''

LISTENER = r'''
import rospy
from std_msgs.msg import String
rospy.init_node("listener")
rospy.Subscriber("chatter", String, lambda m: print("I heard", m.data, flush=True))
print("listening", flush=True)
rospy.spin()
'''


def _ip(*args: str) -> None:
    subprocess.run(["ip", *args], check=True, capture_output=True, timeout=20)


class TwoHosts:
    """Namespaces ``a`` and ``b`` joined by a veth pair, with /etc/hosts naming both (and no
    DNS: ``hosts: files`` in their nsswitch.conf)."""

    def __init__(self, tmp: Path) -> None:
        tag = uuid.uuid4().hex[:6]
        self.ns = {"a": f"minros-a-{tag}", "b": f"minros-b-{tag}"}
        subnet = int(tag[:2], 16) % 250 + 1
        self.ip = {"a": f"10.213.{subnet}.1", "b": f"10.213.{subnet}.2"}
        self.home = tmp / "home"
        (self.home / "log").mkdir(parents=True)
        self.procs: List[Proc] = []
        veth_a, veth_b = f"mra{tag}", f"mrb{tag}"
        _ip("netns", "add", self.ns["a"])
        _ip("netns", "add", self.ns["b"])
        _ip("link", "add", veth_a, "type", "veth", "peer", "name", veth_b)
        for side, veth in (("a", veth_a), ("b", veth_b)):
            _ip("link", "set", veth, "netns", self.ns[side])
            _ip("-n", self.ns[side], "addr", "add", f"{self.ip[side]}/24", "dev", veth)
            _ip("-n", self.ns[side], "link", "set", veth, "up")
            _ip("-n", self.ns[side], "link", "set", "lo", "up")
            etc = Path("/etc/netns") / self.ns[side]
            etc.mkdir(parents=True, exist_ok=True)
            (etc / "hosts").write_text(f"127.0.0.1 localhost\n{self.ip['a']} hosta\n"
                                       f"{self.ip['b']} hostb\n")
            # names come from /etc/hosts alone, as on a small LAN without DNS
            (etc / "nsswitch.conf").write_text("hosts: files\n")

    def env(self, master: str, extra: Dict[str, str], reference: bool = False) -> Dict[str, str]:
        env = ros_env(None, self.home, extra)
        del env["ROS_HOSTNAME"]  # each test sets ROS_HOSTNAME or ROS_IP as a user would
        env.update(extra)
        env["ROS_MASTER_URI"] = master
        return reference_env(env) if reference else env

    def run(self, side: str, argv: List[str], env: Dict[str, str]) -> Proc:
        proc = Proc(["ip", "netns", "exec", self.ns[side], *argv], env)
        self.procs.append(proc)
        return proc

    def call(self, side: str, argv: List[str], env: Dict[str, str],
             timeout: float = 30) -> subprocess.CompletedProcess:
        return subprocess.run(["ip", "netns", "exec", self.ns[side], *argv], env=env,
                              capture_output=True, text=True, timeout=timeout)

    def master(self, side: str, port: int, extra: Dict[str, str] | None = None) -> tuple:
        """``minros core`` in ``side`` advertising its address; (process, master URI)."""
        uri = f"http://{self.ip[side]}:{port}/"
        env = self.env(uri, {"ROS_IP": self.ip[side], **(extra or {})})
        core = self.run(side, [PYTHON, "-m", "minros", "core", "-p", str(port)], env)
        wait_until(lambda: self._answers(side, uri), 20, what="the master")
        return core, uri

    def _answers(self, side: str, uri: str) -> bool:
        probe = ("import sys, xmlrpc.client; "
                 "sys.exit(xmlrpc.client.ServerProxy(sys.argv[1]).getPid('/t')[0] != 1)")
        return self.call(side, [PYTHON, "-c", probe, uri], {}, timeout=10).returncode == 0

    def close(self) -> None:
        for proc in reversed(self.procs):
            proc.stop()
        for ns in self.ns.values():
            subprocess.run(["ip", "netns", "del", ns], capture_output=True, timeout=20)
            shutil.rmtree(Path("/etc/netns") / ns, ignore_errors=True)


@pytest.fixture
def hosts(tmp_path):
    if os.geteuid() != 0:
        pytest.skip("two-host tests create network namespaces, which needs root (CI runs as root)")
    require_reference()
    if shutil.which("ip") is None:
        message = "iproute2's ip is missing (scripts/install-ros-reference.sh installs it)"
        pytest.fail(message) if IN_CI else pytest.skip(message)
    try:
        pair = TwoHosts(tmp_path)
    except subprocess.CalledProcessError as exc:
        message = f"cannot create network namespaces here: {exc.stderr.decode().strip()}"
        pytest.fail(message) if IN_CI else pytest.skip(message)
    try:
        yield pair
    finally:
        pair.close()


def test_rospy_and_minros_talk_across_hosts_both_ways(hosts):
    port = free_port()
    _core, master = hosts.master("a", port)
    # minros listener on the master's host (ROS_IP), Debian rospy talker on the other (ROS_HOSTNAME)
    listener = hosts.run("a", [PYTHON, "-c", LISTENER], hosts.env(master, {"ROS_IP": hosts.ip["a"]}))
    listener.read_until("listening", 20)
    hosts.run("b", [REFERENCE_PYTHON, "-c", TALKER],
              hosts.env(master, {"ROS_HOSTNAME": "hostb"}, reference=True))
    listener.read_until("I heard hello", 20)
    # and the other way: Debian rospy listens on hosta, minros talks from hostb
    rospy_env = hosts.env(master, {"ROS_HOSTNAME": "hosta"}, reference=True)
    rospy_listener = hosts.run("a", [REFERENCE_PYTHON, "-c", LISTENER.replace(
        '"listener"', '"rospy_listener"').replace('"chatter"', '"chatter2"')], rospy_env)
    rospy_listener.read_until("listening", 20)
    hosts.run("b", [PYTHON, "-c", TALKER.replace('"talker"', '"minros_talker"').replace(
        '"chatter"', '"chatter2"')], hosts.env(master, {"ROS_IP": hosts.ip["b"]}))
    rospy_listener.read_until("I heard hello", 20)


def _ping(hosts: TwoHosts, master: str, node: str, reference: bool) -> str:
    tool = ["/usr/bin/rosnode"] if reference else [PYTHON, "-m", "minros", "node"]
    env = hosts.env(master, {"ROS_IP": hosts.ip["a"]}, reference=reference)
    done = hosts.call("a", [*tool, "ping", "-c", "1", node], env)
    return (done.stdout + done.stderr).strip().splitlines()[-1]


@pytest.mark.parametrize("mistake, expected", [
    ({"ROS_HOSTNAME": "talker-host.invalid"},
     "ERROR: Unknown host [talker-host.invalid] for node [/talker]"),
    ({"ROS_IP": "192.0.2.7"}, "connection to [/talker] failed"),
])
def test_classic_network_mistakes_show_as_in_ros(hosts, mistake, expected):
    """A talker on hostb advertising a name hosta cannot resolve, or an address it does not
    have: the master registers it all the same, and rosnode ping on hosta says what is wrong,
    minros's in the words of Debian's."""
    port = free_port()
    _core, master = hosts.master("a", port)
    hosts.run("b", [PYTHON, "-c", TALKER], hosts.env(master, mistake))
    wait_until(lambda: "/talker" in hosts.call(
        "a", [PYTHON, "-m", "minros", "node", "list"], hosts.env(master, {"ROS_IP": hosts.ip["a"]})
    ).stdout, 20, what="the talker registered")
    ours = _ping(hosts, master, "/talker", reference=False)
    theirs = _ping(hosts, master, "/talker", reference=True)
    assert theirs == expected
    assert ours == theirs


def test_allow_list_refuses_the_other_namespace_and_admits_its_own(hosts):
    port = free_port()
    allow = {"ROS_ALLOWED_HOSTS": f"{hosts.ip['a']}/32"}
    core, master = hosts.master("a", port, allow)
    # its own host: a minros pair on hosta works as ever
    listener = hosts.run("a", [PYTHON, "-c", LISTENER], hosts.env(master, {"ROS_IP": hosts.ip["a"]}))
    listener.read_until("listening", 20)
    hosts.run("a", [PYTHON, "-c", TALKER], hosts.env(master, {"ROS_IP": hosts.ip["a"]}))
    listener.read_until("I heard hello", 20)
    # the other namespace: refused, with a line naming the setting on both sides
    stranger = hosts.run("b", [PYTHON, "-c", TALKER.replace('"talker"', '"stranger"')],
                         hosts.env(master, {"ROS_IP": hosts.ip["b"]}))
    rospy_stranger = hosts.run("b", [REFERENCE_PYTHON, "-c", TALKER.replace('"talker"', '"rospy_stranger"')],
                               hosts.env(master, {"ROS_IP": hosts.ip["b"]}, reference=True))
    refusal = f"connection from {hosts.ip['b']} refused: not in ROS_ALLOWED_HOSTS of the master"
    stranger.read_until(refusal, 20)
    seen = core.read_until(refusal, 20)
    nodes = hosts.call("a", [PYTHON, "-m", "minros", "node", "list"],
                       hosts.env(master, {"ROS_IP": hosts.ip["a"]})).stdout.split()
    assert "/talker" in nodes and "/listener" in nodes
    assert "/stranger" not in nodes and "/rospy_stranger" not in nodes
    assert rospy_stranger.alive()  # rospy keeps trying, as it does for a master that is away
    time.sleep(2.0)  # both strangers retry (minros every 0.2 s)
    text = seen + core.stop()
    assert text.count(refusal) == 1  # one line per refused peer, however often it retries


TCPROS_PROBE = r'''
import socket, struct, sys
sock = socket.create_connection((sys.argv[1], int(sys.argv[2])), timeout=5)
fields = [b"topic=/chatter", b"md5sum=*", b"callerid=/probe", b"type=std_msgs/String"]
body = b"".join(struct.pack("<I", len(f)) + f for f in fields)
sock.sendall(struct.pack("<I", len(body)) + body)
data = b""
while True:
    chunk = sock.recv(4096)
    if not chunk:
        break
    data += chunk
print(data[8:].decode(errors="replace"))
'''

REQUEST_TOPIC = r'''
import sys, xmlrpc.client
code, msg, (proto, host, port) = xmlrpc.client.ServerProxy(sys.argv[1]).requestTopic(
    "/probe", "/chatter", [["TCPROS"]])
print(port)
'''


def test_allow_list_on_a_node_refuses_xmlrpc_and_tcpros_from_the_other_namespace(hosts):
    port = free_port()
    _core, master = hosts.master("a", port)  # the master takes everyone
    allow = {"ROS_IP": hosts.ip["a"], "ROS_ALLOWED_HOSTS": f"{hosts.ip['a']}/32"}
    talker = hosts.run("a", [PYTHON, "-c", TALKER], hosts.env(master, allow))
    near = hosts.run("a", [PYTHON, "-c", LISTENER], hosts.env(master, {"ROS_IP": hosts.ip["a"]}))
    far = hosts.run("b", [REFERENCE_PYTHON, "-c", LISTENER.replace('"listener"', '"far"')],
                    hosts.env(master, {"ROS_IP": hosts.ip["b"]}, reference=True))
    near.read_until("I heard hello", 20)  # its own namespace is served
    refusal = (f"connection from {hosts.ip['b']} refused: not in ROS_ALLOWED_HOSTS "
               "of node [/talker]")
    talker.read_until(refusal, 20)  # the far listener's requestTopic, refused
    env_a = hosts.env(master, {"ROS_IP": hosts.ip["a"]})
    uri = f"http://{hosts.ip['a']}:" + hosts.call(
        "a", [PYTHON, "-m", "minros", "node", "info", "/talker"], env_a).stdout.split(
        f"http://{hosts.ip['a']}:", 1)[1].split("/", 1)[0] + "/"
    tcp_port = hosts.call("a", [PYTHON, "-c", REQUEST_TOPIC, uri], env_a).stdout.strip()
    answer = hosts.call("b", [PYTHON, "-c", TCPROS_PROBE, hosts.ip["a"], tcp_port], {}).stdout
    assert answer.strip() == f"error={refusal}"  # the TCPROS server says why, in a header
    time.sleep(1.0)
    far_text = far.stop()
    assert "I heard" not in far_text

