"""Service requests and responses whose type starts with a std_msgs/Header get the sender's
sequence number, as rospy's serialize_message does for every message it sends."""

from __future__ import annotations

import textwrap
from pathlib import Path

from support import PYTHON, Proc, ros_env

SERVER = textwrap.dedent("""
    import rospy
    from stamp_pkg.srv import Stamped, StampedResponse

    def handle(req):
        # answers with the seq the request arrived with; the response's own header is left 0
        return StampedResponse(b=req.header.seq)

    rospy.init_node("stamper")
    rospy.Service("stamped", Stamped, handle)
    print("READY", flush=True)
    rospy.spin()
""")

CLIENT = textwrap.dedent("""
    import rospy
    from stamp_pkg.srv import Stamped, StampedRequest

    proxy = rospy.ServiceProxy("stamped", Stamped)
    proxy.wait_for_service(10)
    for _ in range(3):
        response = proxy(StampedRequest(a=7))
        print("SEQ", response.b, response.header.seq, flush=True)
""")


def _package(root: Path) -> Path:
    pkg = root / "stamp_pkg"
    (pkg / "srv").mkdir(parents=True)
    (pkg / "package.xml").write_text(
        '<?xml version="1.0"?>\n<package format="2"><name>stamp_pkg</name><version>0.0.1</version>'
        '<description>test</description><maintainer email="a@b.c">a</maintainer>'
        '<license>BSD</license></package>\n')
    (pkg / "srv" / "Stamped.srv").write_text("Header header\nint32 a\n---\nHeader header\nint32 b\n")
    return root


def test_request_and_response_headers_carry_the_sender_seq(minros_master: int, ros_home: Path,
                                                           tmp_path: Path) -> None:
    env = ros_env(minros_master, ros_home)
    env["ROS_PACKAGE_PATH"] = str(_package(tmp_path / "src"))
    (tmp_path / "server.py").write_text(SERVER)
    (tmp_path / "client.py").write_text(CLIENT)
    server = Proc([PYTHON, str(tmp_path / "server.py")], env)
    try:
        server.read_until("READY", 30)
        client = Proc([PYTHON, str(tmp_path / "client.py")], env)
        try:
            out = client.read_until("SEQ 3", 30)
        finally:
            client.stop()
    finally:
        server.stop()
    seqs = [line.split()[1:] for line in out.splitlines() if line.startswith("SEQ")]
    # the client numbers its requests 1, 2, 3; the server its responses 1, 2, 3
    assert seqs == [["1", "1"], ["2", "2"], ["3", "3"]], out
