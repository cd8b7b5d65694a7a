"""minros nodes on the minros master: publish/subscribe, the slave API, bad input, slow peers."""

from __future__ import annotations

import re
import socket
import struct
import time
import xmlrpc.client
from pathlib import Path

import pytest

from integration.pubsub_scripts import LISTENER, TALKER
from minros.wire import tcpros
from support import PYTHON, Proc, ros_env, wait_until

STRING_MD5 = "992ce8a1687cec8c8bd883ec73ca41d1"


@pytest.fixture
def scripts(tmp_path: Path):
    talker = tmp_path / "talker.py"
    listener = tmp_path / "listener.py"
    talker.write_text(TALKER)
    listener.write_text(LISTENER)
    return talker, listener


def _node(script: Path, args, port: int, home: Path, extra=None) -> Proc:
    return Proc([PYTHON, str(script), *map(str, args)], ros_env(port, home, extra))


def _master(port: int) -> xmlrpc.client.ServerProxy:
    return xmlrpc.client.ServerProxy(f"http://127.0.0.1:{port}/")


def _lookup(port: int, prefix: str) -> str:
    """URI of the one node whose name starts with ``prefix`` (anonymous names)."""
    def find():
        code, _, state = _master(port).getSystemState("/test")
        for _topic, nodes in state[0]:
            for name in nodes:
                if name.startswith(prefix):
                    code, _, uri = _master(port).lookupNode("/test", name)
                    if code == 1:
                        return name, uri
        return None
    return wait_until(find, 15, what=f"node {prefix} registered")


@pytest.fixture
def latched_talker(scripts, minros_master, ros_home):
    """A minros node publishing one latched String on /latched; yields (name, uri, port)."""
    talker, _ = scripts
    proc = _node(talker, ["/latched", "string", 1, 10, 1], minros_master, ros_home)
    try:
        proc.read_until("published latched", 20)
        name, uri = _lookup(minros_master, "/talker")
        yield name, uri, proc
    finally:
        proc.stop()


def test_minros_pair_in_order(scripts, minros_master, ros_home):
    talker, listener = scripts
    sub = _node(listener, ["/chatter", "string", 30], minros_master, ros_home)
    pub = None
    try:
        sub.read_until("subscribed", 20)
        pub = _node(talker, ["/chatter", "string", 30, 200, 0], minros_master, ros_home)
        out = sub.read_until("listener done 30", 20)
    finally:
        sub.stop()
        if pub:
            pub.stop()
    assert [x for x in out.splitlines() if x.startswith("got")] == [
        f"got msg {i} from /talker" for i in range(30)]


def test_two_subscriptions_share_one_connection_and_late_callback_gets_latched(
        tmp_path, latched_talker, minros_master, ros_home):
    script = tmp_path / "two_subs.py"
    script.write_text(r'''
import rospy, threading
from std_msgs.msg import String
got = []
done = threading.Event()
def cb(m, tag):
    got.append((tag, m.data))
    if len(got) >= 2:
        done.set()
rospy.init_node("twosubs")
a = rospy.Subscriber("/latched", String, cb, callback_args="a")
while not got and not rospy.is_shutdown():
    rospy.sleep(0.01)
b = rospy.Subscriber("/latched", String, cb, callback_args="b")  # registered after the latch arrived
done.wait(10)
import xmlrpc.client
info = xmlrpc.client.ServerProxy(rospy.get_node_uri()).getBusInfo("/x")[2]
print("GOT", sorted(got), "CONNECTIONS", len([c for c in info if c[4] == "/latched"]), flush=True)
''')
    proc = Proc([PYTHON, str(script)], ros_env(minros_master, ros_home))
    out = proc.read_until("GOT", 20)
    proc.stop()
    assert "GOT [('a', 'msg 0'), ('b', 'msg 0')] CONNECTIONS 1" in out


@pytest.mark.smoke
def test_slave_api_answers_and_errors(latched_talker, scripts, minros_master, ros_home):
    name, uri, proc = latched_talker
    node = xmlrpc.client.ServerProxy(uri)
    assert node.getPid("/t") == [1, "", proc.pid]
    assert node.getName("/t")[2] == name
    assert node.getUri("/t")[2] == uri
    code, _, master_uri = node.getMasterUri("/t")
    assert code == 1 and master_uri.endswith(f":{minros_master}")
    pubs = node.getPublications("/t")[2]
    assert ["/latched", "std_msgs/String"] in pubs and ["/rosout", "rosgraph_msgs/Log"] in pubs
    assert node.getSubscriptions("/t") == [1, "subscriptions", []]
    # requestTopic: protocol negotiation and its errors
    code, _, proto = node.requestTopic("/t", "/latched", [["FakeTransport", 1234, 5678], ["TCPROS"]])
    assert code == 1 and proto[0] == "TCPROS" and isinstance(proto[2], int)
    assert node.requestTopic("/t", "/latched", [["UDPROS"]])[0] == 0
    assert node.requestTopic("/t", "/latched", "TCPROS")[0] == -1
    assert node.requestTopic("/t", "/nope", [["TCPROS"]]) == [-1, "Not a publisher of [/nope]", []]
    # publisherUpdate: validated, accepted for topics we do not subscribe
    assert node.publisherUpdate("/t", "/x", "http://a:1/")[0] == -1
    assert node.publisherUpdate("/t", "/x", ["not a uri"])[0] == -1
    assert node.publisherUpdate("/t", "/x", ["http://localhost:1/"])[0] == 1
    assert node.paramUpdate("/t", "relative", 1)[0] == -1
    assert node.paramUpdate("/t", "/not_subscribed", 1) == [-1, "not subscribed", 0]
    # arity and caller_id checks
    assert node.getPid()[:2] == [-1, "missing required caller_id parameter"]
    assert node.getPid("/t", "extra")[:2] == [-1, "Error: bad call arity"]
    assert node.getPid(5)[:2] == [-1, "caller_id must be a string"]
    stats = node.getBusStats("/t")
    assert stats[0] == 1 and any(p[0] == "/latched" for p in stats[2][0])


def test_bus_info_string_parses_like_rosnode(latched_talker, scripts, minros_master, ros_home):
    """A TCPROS connection's line (a listener kept off shared memory: MINROS_SHM=0)."""
    _, uri, _ = latched_talker
    _, listener = scripts
    sub = _node(listener, ["/latched", "string", 1000], minros_master, ros_home,
                {"MINROS_SHM": "0"})
    try:
        sub.read_until("got msg 0", 20)
        info = xmlrpc.client.ServerProxy(uri).getBusInfo("/t")[2]
        (conn,) = [c for c in info if c[4] == "/latched"]
        assert conn[2] == "o" and conn[3] == "TCPROS" and conn[1].startswith("/listener")
        match = re.match(r"\w+ connection on port (\d+) to \[(.*) on socket (\d+)\]", conn[6])
        assert match, conn[6]
        sub_name, sub_uri = _lookup(minros_master, "/listener")
        sub_info = xmlrpc.client.ServerProxy(sub_uri).getBusInfo("/t")[2]
        (inbound,) = [c for c in sub_info if c[4] == "/latched"]
        assert inbound[1] == uri and inbound[2] == "i"
    finally:
        sub.stop()


def test_two_minros_nodes_of_one_host_take_shared_memory(latched_talker, scripts, minros_master,
                                                         ros_home):
    """Between minros nodes of one host the connection is MINROSSHM, on both sides' bus info."""
    _, uri, _ = latched_talker
    _, listener = scripts
    sub = _node(listener, ["/latched", "string", 1000], minros_master, ros_home)
    try:
        sub.read_until("got msg 0", 20)
        info = xmlrpc.client.ServerProxy(uri).getBusInfo("/t")[2]
        (conn,) = [c for c in info if c[4] == "/latched"]
        assert conn[2] == "o" and conn[3] == "MINROSSHM" and conn[1].startswith("/listener")
        assert re.match(r"MINROSSHM connection \(shared memory, .*\) on Unix socket \d+ to "
                        r"\[pid \d+\]", conn[6]), conn[6]
        _, sub_uri = _lookup(minros_master, "/listener")
        (inbound,) = [c for c in xmlrpc.client.ServerProxy(sub_uri).getBusInfo("/t")[2]
                      if c[4] == "/latched"]
        assert inbound[1] == uri and inbound[3] == "MINROSSHM"
    finally:
        sub.stop()


def test_shutdown_request_unregisters_everything(latched_talker, minros_master):
    name, uri, proc = latched_talker
    assert xmlrpc.client.ServerProxy(uri).shutdown("/t", "test over")[0] == 1
    proc.popen.wait(10)
    assert "shutdown request: test over" in proc.output()
    # one multicall took every registration away: the master forgot the node
    assert _master(minros_master).lookupNode("/t", name)[0] == -1


# ------------------------------------------------------------------------------ bad input


def _tcpros_address(uri: str, topic: str):
    code, _, proto = xmlrpc.client.ServerProxy(uri).requestTopic("/t", topic, [["TCPROS"]])
    assert code == 1
    return proto[1], proto[2]


def _raw(address, data: bytes, read: bool = True) -> bytes:
    with socket.create_connection(address, timeout=5) as sock:
        sock.sendall(data)
        if not read:
            return b""
        chunks = []
        while True:
            try:
                chunk = sock.recv(65536)
            except ConnectionResetError:
                break
            if not chunk:
                break
            chunks.append(chunk)
        return b"".join(chunks)


def _error_of(reply: bytes) -> str:
    fields, _ = tcpros.read_header_block(reply)
    return fields["error"]


def test_publisher_rejects_bad_handshakes_and_stays_healthy(latched_talker, scripts, minros_master, ros_home):
    _, uri, proc = latched_talker
    address = _tcpros_address(uri, "/latched")
    base = {"topic": "/latched", "callerid": "/evil", "md5sum": STRING_MD5, "type": "std_msgs/String"}
    missing = {k: v for k, v in base.items() if k != "md5sum"}
    assert _error_of(_raw(address, tcpros.encode_header(missing))) == "Missing required 'md5sum' field"
    wrong = {**base, "md5sum": "0" * 32}
    assert _error_of(_raw(address, tcpros.encode_header(wrong))) == (
        "Client [/evil] wants topic [/latched] to have datatype/md5sum "
        f"[std_msgs/String/{'0' * 32}], but our version has [std_msgs/String/{STRING_MD5}] "
        "Dropping connection.")
    wrong_type = {**wrong, "type": "std_msgs/Int32"}
    assert _error_of(_raw(address, tcpros.encode_header(wrong_type))) == (
        "topic types do not match: [std_msgs/Int32] vs. [std_msgs/String]")
    assert _error_of(_raw(address, tcpros.encode_header({"callerid": "/x"}))) == (
        "no topic or service name detected")
    # garbage, an oversize length, a truncated header, a header field overrunning its block
    assert _raw(address, b"\xff\xff\xff\xff garbage") == b""
    assert _raw(address, struct.pack("<I", 100) + b"short", read=False) == b""
    assert _raw(address, struct.pack("<I", 8) + struct.pack("<I", 50) + b"abcd") == b""
    # still healthy: a real subscriber gets the latched message
    _, listener = scripts
    sub = _node(listener, ["/latched", "string", 1], minros_master, ros_home)
    out = sub.read_until("listener done 1", 20)
    sub.stop()
    assert "got msg 0" in out
    assert proc.alive()
    log = proc.stop()
    assert "Traceback" not in log
    # one WARN line per rejected or broken connection, in rospy's words
    warnings = [x for x in log.splitlines() if x.startswith("[WARN]")]
    assert len([x for x in warnings if "Could not process inbound connection: " in x]) == 4
    assert len([x for x in warnings if "Inbound TCP/IP connection failed: " in x]) == 3, log
    assert any("Missing required 'md5sum' field{" in x for x in warnings)


def test_wildcard_subscriber_gets_definition(latched_talker):
    _, uri, _ = latched_talker
    address = _tcpros_address(uri, "/latched")
    header = {"topic": "/latched", "callerid": "/any", "md5sum": "*", "type": "*"}
    with socket.create_connection(address, timeout=5) as sock:
        sock.sendall(tcpros.encode_header(header))
        reader = tcpros.FrameReader()
        frames: list = []
        while len(frames) < 2:
            frames += reader.feed(sock.recv(65536))
    fields = tcpros.decode_header(frames[0])
    assert fields["type"] == "std_msgs/String" and fields["md5sum"] == STRING_MD5
    assert fields["latching"] == "1" and fields["message_definition"] == "string data\n"
    assert bytes(frames[1]) == struct.pack("<I", 5) + b"msg 0"


FLOODER = r'''
import os, sys, time, resource
import rospy
from std_msgs.msg import UInt8MultiArray
rospy.init_node("flooder")
pub = rospy.Publisher("/flood", UInt8MultiArray, queue_size=5)
print("ready", flush=True)
while pub.get_num_connections() < int(sys.argv[1]):
    time.sleep(0.01)
payload = bytes(100_000)
rss0 = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss
start = time.monotonic()
for i in range(2000):
    pub.publish(UInt8MultiArray(data=payload))
elapsed = time.monotonic() - start
rss1 = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss
print("published 2000 in %.2f s, rss grew %d kB" % (elapsed, rss1 - rss0), flush=True)
rospy.spin()
'''


def test_subscriber_that_never_reads_does_not_block_or_bloat(tmp_path, minros_master, ros_home):
    script = tmp_path / "flooder.py"
    script.write_text(FLOODER)
    proc = _node(script, [1], minros_master, ros_home)
    try:
        proc.read_until("ready", 20)
        name, uri = _lookup(minros_master, "/flooder")
        address = _tcpros_address(uri, "/flood")
        with socket.create_connection(address, timeout=5) as stuck:
            stuck.setsockopt(socket.SOL_SOCKET, socket.SO_RCVBUF, 4096)
            stuck.sendall(tcpros.encode_header({
                "topic": "/flood", "callerid": "/stuck", "md5sum": "*", "type": "*"}))
            out = proc.read_until("published 2000", 30)  # 200 MB offered to a peer that never reads
            line = [x for x in out.splitlines() if x.startswith("published")][0]
            seconds, grew = re.match(r"published 2000 in ([\d.]+) s, rss grew (\d+) kB", line).groups()
            assert float(seconds) < 15
            assert int(grew) < 60_000  # queue of 5 x 100 kB plus kernel buffers, not 200 MB
            assert proc.alive()
    finally:
        proc.stop()


def test_garbage_from_a_publisher_drops_only_that_connection(tmp_path, minros_master, ros_home, scripts):
    """A fake publisher sends an oversize frame; the subscriber logs one line and keeps working."""
    from minros.wire.xmlrpc import XmlRpcServer

    server = socket.socket()
    server.bind(("127.0.0.1", 0))
    server.listen(4)
    tcp_port = server.getsockname()[1]

    class FakeSlave:
        def requestTopic(self, caller_id, topic, protocols):
            return [1, "", ["TCPROS", "127.0.0.1", tcp_port]]

        def getPid(self, caller_id):
            return [1, "", 0]

    xml = XmlRpcServer(FakeSlave(), host="127.0.0.1", port=0).start()
    fake_uri = f"http://127.0.0.1:{xml.port}/"
    _, listener = scripts
    sub = _node(listener, ["/mixed", "string", 3], minros_master, ros_home)
    good = None
    try:
        sub.read_until("subscribed", 20)
        _master(minros_master).registerPublisher("/fake", "/mixed", "std_msgs/String", fake_uri)
        server.settimeout(10)
        conn, _ = server.accept()
        conn.settimeout(5)
        conn.recv(65536)  # the subscriber's header
        conn.sendall(tcpros.encode_header({"md5sum": STRING_MD5, "type": "std_msgs/String",
                                           "callerid": "/fake"}))
        conn.sendall(tcpros.encode_frame(struct.pack("<I", 4) + b"fine"))
        conn.sendall(struct.pack("<I", 0xFFFFFFF0) + b"junk")  # a lying length: dropped
        sub.read_until("got fine from /fake", 10)
        wait_until(lambda: conn.recv(10) == b"", 10, what="subscriber closed the bad connection")
        conn.close()
        _master(minros_master).unregisterPublisher("/fake", "/mixed", fake_uri)
        talker, _ = scripts
        good = _node(talker, ["/mixed", "string", 2, 20, 0], minros_master, ros_home)
        out = sub.read_until("listener done 3", 20)
        assert "got msg 0 from /talker" in out and "got msg 1 from /talker" in out
        assert len([x for x in out.splitlines() if "exceeds the limit" in x]) == 1
        assert "Traceback" not in out
    finally:
        sub.stop()
        if good:
            good.stop()
        xml.shutdown()
        server.close()


# ------------------------------------------------------------------------------ master restart


def test_master_restart_reregisters_and_reconnects(scripts, ros_home):
    from support import free_port, wait_for_master

    port = free_port()
    talker, listener = scripts

    def start_master():
        proc = Proc([PYTHON, "-m", "minros.master", "-p", str(port)], ros_env(port, ros_home))
        wait_for_master(port)
        return proc

    master = start_master()
    sub = _node(listener, ["/restart", "string", 100000], port, ros_home)
    pub = _node(talker, ["/restart", "string", 100000, 20, 0], port, ros_home)
    pub2 = None
    try:
        sub.read_until("got msg 3 from /talker", 20)
        master.stop()
        time.sleep(0.5)
        master = start_master()

        def registered():
            state = _master(port).getSystemState("/t")[2]
            pubs = dict((t, n) for t, n in state[0])
            subs = dict((t, n) for t, n in state[1])
            return pubs.get("/restart") and subs.get("/restart")
        wait_until(registered, 10, what="publisher and subscriber registered with the new master")
        # a publisher that comes back as a new process (new ports) is found through the new master
        pub.stop()
        pub2 = _node(talker, ["/restart", "string", 100000, 20, 0, "__name:=talker2"], port, ros_home)
        pub2.read_until("subscriber connected", 15)
        sub.read_until("from /talker2", 15)
    finally:
        for proc in (sub, pub, pub2, master):
            if proc is not None:
                proc.stop()


SYNC_FLOODER = r'''
import time
import rospy
import minros.transport.sendqueue
from std_msgs.msg import UInt8MultiArray
minros.transport.sendqueue.SYNC_SEND_TIMEOUT = 1.0  # rospy's socket timeout is 60 s; shortened for the test
rospy.init_node("sync_flooder")
pub = rospy.Publisher("/sync_flood", UInt8MultiArray, queue_size=None)
print("ready", flush=True)
while pub.get_num_connections() < 1:
    time.sleep(0.01)
start = time.monotonic()
for i in range(200):
    pub.publish(UInt8MultiArray(data=bytes(100_000)))
print("published 200 in %.1f s, connections left %d" % (time.monotonic() - start, pub.get_num_connections()), flush=True)
'''


def test_synchronous_publisher_gives_up_on_a_stuck_subscriber(tmp_path, minros_master, ros_home):
    script = tmp_path / "sync_flooder.py"
    script.write_text(SYNC_FLOODER)
    proc = _node(script, [], minros_master, ros_home)
    try:
        proc.read_until("ready", 20)
        _name, uri = _lookup(minros_master, "/sync_flooder")
        with socket.create_connection(_tcpros_address(uri, "/sync_flood"), timeout=5) as stuck:
            stuck.setsockopt(socket.SOL_SOCKET, socket.SO_RCVBUF, 4096)
            stuck.sendall(tcpros.encode_header({
                "topic": "/sync_flood", "callerid": "/stuck", "md5sum": "*", "type": "*"}))
            out = proc.read_until("published 200", 30)
        seconds, left = re.search(r"published 200 in ([\d.]+) s, connections left (\d+)", out).groups()
        # blocked about the timeout once, then the dead-weight connection was dropped
        assert 0.8 < float(seconds) < 10 and left == "0"
    finally:
        proc.stop()
