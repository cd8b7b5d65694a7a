"""rospy.impl's transports (minros.rospy_internals) against Debian's rospy: a TCPROSTransport
asks a real rospy publisher for its topic and reads its messages; a real rospy subscriber is
served through TCPROSHandler.topic_connection_handler."""

from __future__ import annotations

import socket
import threading
from pathlib import Path

import pytest

from support import REFERENCE_PYTHON, Proc, reference_env, ros_env, wait_until

pytestmark = pytest.mark.interop

TALKER = r'''
import rospy
from geometry_msgs.msg import PointStamped
rospy.init_node("debian_talker")
pub = rospy.Publisher("/impl_chat", PointStamped, queue_size=10)
i = 0
while not rospy.is_shutdown():
    i += 1
    m = PointStamped()
    m.header.frame_id = "debian"
    m.point.x = float(i)
    pub.publish(m)
    rospy.sleep(0.05)
'''

LISTENER = r'''
import sys
import rospy
from std_msgs.msg import String
rospy.init_node("debian_listener")
got = []
rospy.Subscriber("/impl_served", String, lambda m: (got.append(m.data), print("got", m.data, flush=True)))
rospy.spin()
'''


def test_transport_reads_a_debian_rospy_publisher(debian_rosmaster: int, ros_home: Path,
                                                  tmp_path: Path):
    import xmlrpc.client

    from geometry_msgs.msg import PointStamped
    from rospy.impl.tcpros_base import TCPROSTransport
    from rospy.impl.tcpros_pubsub import TCPROSSub

    env = ros_env(debian_rosmaster, ros_home)
    (tmp_path / "talker.py").write_text(TALKER)
    talker = Proc([REFERENCE_PYTHON, str(tmp_path / "talker.py")], reference_env(env))
    try:
        master = xmlrpc.client.ServerProxy(env["ROS_MASTER_URI"])
        wait_until(lambda: any(t == "/impl_chat" for t, _ in master.getPublishedTopics("/t", "")[2]),
                   20, what="the Debian talker")
        uri = master.lookupNode("/t", "/debian_talker")[2]
        code, _msg, params = xmlrpc.client.ServerProxy(uri).requestTopic("/t", "/impl_chat", [["TCPROS"]])
        assert code == 1 and params[0] == "TCPROS"
        client = TCPROSTransport(TCPROSSub("/impl_chat", PointStamped), "/impl_chat")
        client.connect(params[1], params[2], uri, timeout=10)
        assert client.callerid_pub == "/debian_talker" and client.md5sum == PointStamped._md5sum
        got = []
        while len(got) < 3:
            got += client.receive_once()
        assert all(m.header.frame_id == "debian" for m in got)
        assert [m.point.x for m in got] == sorted(m.point.x for m in got)
        client.close()
    finally:
        talker.stop()


def test_topic_connection_handler_serves_a_debian_rospy_subscriber(debian_rosmaster: int,
                                                                   ros_home: Path, tmp_path: Path):
    from minros.wire import sockets, tcpros
    from rospy.impl.registration import get_topic_manager
    from rospy.impl.tcpros_base import TCPServer
    from rospy.impl.tcpros_pubsub import TCPROSHandler
    from std_msgs.msg import String

    handler = TCPROSHandler()
    tm = get_topic_manager()
    impl = tm.acquire_impl("pub", "/impl_served", String)

    def inbound(sock: socket.socket, addr) -> None:
        header = sockets.read_header(sock)
        error = handler.topic_connection_handler(sock, addr, header)
        if error:
            sock.sendall(tcpros.encode_header({"error": error}))
            sockets.close(sock)

    server = TCPServer(inbound)
    server.start()
    import xmlrpc.client
    from xmlrpc.server import SimpleXMLRPCServer

    # a stand-in slave API answering requestTopic with the TCPServer's address
    slave = SimpleXMLRPCServer(("127.0.0.1", 0), logRequests=False, allow_none=True)
    slave.register_function(lambda caller, topic, protocols: [1, "", ["TCPROS", "127.0.0.1", server.port]],
                            "requestTopic")
    threading.Thread(target=slave.serve_forever, daemon=True).start()
    slave_uri = f"http://127.0.0.1:{slave.server_address[1]}/"
    env = ros_env(debian_rosmaster, ros_home)
    master = xmlrpc.client.ServerProxy(env["ROS_MASTER_URI"])
    master.registerPublisher("/impl_pub", "/impl_served", "std_msgs/String", slave_uri)
    (tmp_path / "listener.py").write_text(LISTENER)
    listener = Proc([REFERENCE_PYTHON, str(tmp_path / "listener.py")], reference_env(env))
    try:
        wait_until(impl.has_connections, 20, what="the Debian subscriber connected")
        assert impl.has_connection("/debian_listener")
        impl.publish(String("served by rospy.impl"))
        listener.read_until("got served by rospy.impl", 10)
    finally:
        listener.stop()
        slave.shutdown()
        server.shutdown()
        tm.release_impl("pub", "/impl_served")
