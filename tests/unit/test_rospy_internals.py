"""rospy's internal modules over minros (minros.rospy_internals): the managers are the node's,
the transports speak TCPROS byte for byte, the module globals are the node's state."""

from __future__ import annotations

import io
import socket
import struct
import threading

import pytest

import rospy
import rospy.core
import rospy.impl.registration as registration
import rospy.impl.transport
import rospy.msg
import rospy.names
from geometry_msgs.msg import PointStamped
from minros import node as minros_node
from minros.wire import sockets, tcpros
from rospy.impl.tcpros_base import TCPROSTransport, TCPServer
from rospy.impl.tcpros_pubsub import TCPROSHandler, TCPROSPub, TCPROSSub
from rospy.impl.tcpros_service import service_connection_handler
from std_msgs.msg import Header, String
from std_srvs.srv import Empty
from support import run_python


def test_the_stand_ins_are_the_adapter_modules():
    import minros.rospy_internals.core as core
    import minros.rospy_internals.registration as reg

    assert rospy.core is core and registration is reg
    assert rospy.names.get_name() == minros_node.get_caller_id()
    assert rospy.names._mappings is minros_node.default_node().names.argv_mappings


def test_topic_manager_is_the_nodes_registry():
    tm = registration.get_topic_manager()
    impl = tm.acquire_impl(registration.Registration.PUB, "/rospy_internals/t", String)
    try:
        assert minros_node.default_node().publications["/rospy_internals/t"] is impl
        assert tm.get_publisher_impl("/rospy_internals/t") is impl
        assert ["/rospy_internals/t", "std_msgs/String"] in tm.get_publications()
        pub = rospy.Publisher("/rospy_internals/t", String, queue_size=1)
        assert pub.impl is impl and impl.ref_count == 2
        pub.unregister()
    finally:
        tm.release_impl(registration.Registration.PUB, "/rospy_internals/t")
    assert tm.get_publisher_impl("/rospy_internals/t") is None


def test_topic_connection_handler_checks_the_header():
    handler = TCPROSHandler()
    fields = {"topic": "/rospy_internals/u", "md5sum": String._md5sum, "callerid": "/peer"}
    assert handler.topic_connection_handler(None, ("h", 1), {"topic": "/x"}) == "Missing required 'md5sum' field"
    assert "is not a publisher of [/rospy_internals/u]" in handler.topic_connection_handler(None, ("h", 1), fields)
    tm = registration.get_topic_manager()
    tm.acquire_impl("pub", "/rospy_internals/u", String)
    try:
        bad = dict(fields, md5sum="0" * 32, type="std_msgs/Int8")
        assert handler.topic_connection_handler(None, ("h", 1), bad) == \
            "topic types do not match: [std_msgs/Int8] vs. [std_msgs/String]"
    finally:
        tm.release_impl("pub", "/rospy_internals/u")


def test_service_manager_and_connection_handler():
    from rospy.service import _Service

    sm = registration.get_service_manager()
    record = _Service("/rospy_internals/srv", Empty)
    sm.register("/rospy_internals/srv", record)
    try:
        assert sm.get_service("/rospy_internals/srv") is record
        assert "/rospy_internals/srv" in minros_node.default_node().services
        header = {"service": "/rospy_internals/srv", "md5sum": "x", "callerid": "/c"}
        assert service_connection_handler(None, ("h", 1), header) == \
            f"request from [/c]: md5sums do not match: [x] vs. [{Empty._md5sum}]"
        assert "Missing required 'callerid'" in service_connection_handler(None, ("h", 1), {
            "service": "/s", "md5sum": "*"})
    finally:
        sm.unregister("/rospy_internals/srv", record)
    assert sm.get_service("/rospy_internals/srv") is None


def test_transport_pair_speaks_tcpros():
    """A publisher-side transport served by TCPServer and a subscriber-side one connected to
    it: headers both ways, three messages, seq stamped."""
    served = threading.Event()

    def inbound(sock: socket.socket, addr) -> None:
        header = sockets.read_header(sock)
        assert header["topic"] == "/chat" and header["md5sum"] == PointStamped._md5sum
        out = TCPROSTransport(TCPROSPub("/chat", PointStamped, is_latch=True), "/chat")
        out.set_socket(sock, header["callerid"])
        out.write_header()
        for seq in (1, 2, 3):
            out.send_message(PointStamped(header=Header(frame_id=f"f{seq}")), seq)
        served.set()

    server = TCPServer(inbound)
    server.start()
    try:
        client = TCPROSTransport(TCPROSSub("/chat", PointStamped), "/chat")
        client.connect("127.0.0.1", server.port, "http://peer:1/", timeout=10)
        assert client.is_latched and client.type == "geometry_msgs/PointStamped"
        got = []
        while len(got) < 3:
            got += client.receive_once()
        assert [(m.header.seq, m.header.frame_id) for m in got] == [(1, "f1"), (2, "f2"), (3, "f3")]
        assert client.latch.header.frame_id == "f3" and got[0]._connection_header["latching"] == "1"
        assert served.wait(5)
        client.close()
        assert client.socket is None and client.done
    finally:
        server.shutdown()


def test_a_huge_announced_frame_ends_the_connection():
    def inbound(sock: socket.socket, addr) -> None:
        sockets.read_header(sock)
        sock.sendall(tcpros.encode_header({"type": "std_msgs/String", "md5sum": String._md5sum}))
        sock.sendall(struct.pack("<I", 0xFFFFFFF0) + b"x" * 100)

    server = TCPServer(inbound)
    server.start()
    try:
        client = TCPROSTransport(TCPROSSub("/big", String), "/big")
        client.connect("127.0.0.1", server.port, "peer", timeout=10)
        with pytest.raises(rospy.exceptions.TransportException, match="exceeds the limit"):
            client.receive_once()
        client.close()
    finally:
        server.shutdown()


def test_deserialize_messages_keeps_the_tail_and_the_newest():
    frames = []
    for text in ("a", "bb", "ccc"):
        buff = io.BytesIO()
        rospy.msg.serialize_message(buff, 0, String(text))
        frames.append(buff.getvalue())
    b = io.BytesIO()
    b.write(b"".join(frames) + frames[0][:3])
    queue = []
    rospy.msg.deserialize_messages(b, queue, String, queue_size=2)
    assert [m.data for m in queue] == ["bb", "ccc"] and b.getvalue() == frames[0][:3]
    with pytest.raises(rospy.exceptions.ROSSerializationException):
        rospy.msg.serialize_message(io.BytesIO(), 0, String(data=5))


@pytest.mark.slow
def test_shutdown_hooks_run_in_rospys_order_and_the_flag_resets():
    code = r'''
import rospy.core as core
order = []
core.add_shutdown_hook(lambda r: order.append(("shutdown", r, core.is_shutdown())))
core.add_preshutdown_hook(lambda r: order.append(("pre", core.is_shutdown())))
core.add_client_shutdown_hook(lambda: order.append(("client", core.is_shutdown())))
core.signal_shutdown("done")
assert order == [("client", False), ("pre", False), ("shutdown", "done", True)], order
late = []
core.add_shutdown_hook(late.append)
assert late == ["already shutdown"] and core._shutdown_flag
core._shutdown_flag = False
assert not core.is_shutdown() and not core._in_shutdown
import rospy
pub = rospy.Publisher("/after_reset", __import__("std_msgs.msg").msg.String, queue_size=1)
assert pub.impl.node is core._node.default_node()
print("ok")
'''
    out = run_python(code, {})
    assert out.returncode == 0, out.stderr
    assert out.stdout.strip() == "ok"


class _Capture(rospy.impl.transport.Transport):
    """A rospy transport of rospy code's own (as rospy's tests write them)."""

    def __init__(self, endpoint_id: str) -> None:
        super().__init__(rospy.impl.transport.OUTBOUND, endpoint_id)
        self.endpoint_id = endpoint_id
        self.data = b""

    def write_data(self, data: bytes) -> bool:
        self.data += data
        self.stat_bytes += len(data)
        self.stat_num_msg += 1
        return True


def _frame(msg) -> bytes:
    buff = io.BytesIO()
    rospy.msg.serialize_message(buff, 0, msg)
    return buff.getvalue()


def test_a_rospy_transport_is_a_connection_of_the_publication():
    """rospy's Transport is a transport of minros's seam: the node's publication sends it the
    latched message, frames it through write_data, counts and lists it by its endpoint."""
    from minros.transport.base import Transport as SeamTransport

    tm = registration.get_topic_manager()
    impl = tm.acquire_impl("pub", "/rospy_internals/seam", String)
    try:
        impl.is_latch = True
        impl.publish(String("latched"))
        a, b = _Capture("/a"), _Capture("/b")
        assert isinstance(a, SeamTransport)
        assert impl.add_connection(a) and impl.add_connection(b)
        assert a.data == b.data == _frame(String("latched"))
        impl.publish(String("only b"), connection_override=b)
        assert b.data.endswith(_frame(String("only b"))) and a.data == _frame(String("latched"))
        assert impl.has_connection("/a") and not impl.has_connection("/c")
        assert impl.get_num_connections() == 2 and impl.latch.data == "only b"
        info = {row[1]: row for row in impl.get_stats_info()}
        assert info["/a"][:4] == [a.id, "/a", "o", "UNKNOWN"]
        assert info["/a"][6] == "UNKNOWN connection to [/a]"
        assert [a.id, len(a.data), 1, True] in impl.get_stats()[2]
        impl.remove_connection(a)
        assert not impl.has_connection("/a") and impl.has_connection("/b")
    finally:
        tm.release_impl("pub", "/rospy_internals/seam")


def test_topic_connection_handler_replaces_a_subscribers_old_connection():
    """An inbound subscriber checked by rospy's handler joins the node's publication as a
    rospy TCPROSTransport; the same subscriber connecting again replaces it, and a transport
    that closes leaves the publication."""
    tm = registration.get_topic_manager()
    impl = tm.acquire_impl("pub", "/rospy_internals/served", String)
    handler = TCPROSHandler()
    header = {"topic": "/rospy_internals/served", "md5sum": String._md5sum, "callerid": "/sub"}
    pairs = [socket.socketpair() for _ in range(2)]
    try:
        for ours, theirs in pairs:
            theirs.settimeout(5)
            assert handler.topic_connection_handler(ours, ("h", 1), header) is None
            assert sockets.read_header(theirs)["type"] == "std_msgs/String"
        assert len(impl.connections) == 1 and impl.has_connection("/sub")
        assert pairs[0][1].recv(1) == b""  # the first connection was closed
        impl.publish(String("to the second"))
        second = pairs[1][1]
        assert struct.unpack("<I", second.recv(4))[0] == len(_frame(String("to the second"))) - 4
        impl.connections[0].close()
        assert not impl.has_connections()
    finally:
        tm.release_impl("pub", "/rospy_internals/served")
        for pair in pairs:
            for sock in pair:
                sock.close()
