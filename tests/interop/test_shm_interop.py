"""MINROSSHM is negotiated, never imposed: Debian's rospy and roscpp publishers answer the
minros subscriber's offer ([MINROSSHM, ...], [TCPROS]) with TCPROS, their subscribers never
offer it, and 1080p images flow both ways over TCPROS while each side's bus info says so."""

from __future__ import annotations

import re
import xmlrpc.client
from pathlib import Path

import pytest

from integration.pubsub_scripts import LISTENER, TALKER
from interop.test_pubsub_roscpp import NODE_CPP
from minros.transport import shm as shm_transport
from minros.wire import shm as wire_shm
from support import (
    PYTHON,
    REFERENCE_PYTHON,
    Proc,
    build_roscpp,
    reference_env,
    require_reference,
    ros_env,
    wait_until,
)

pytestmark = [pytest.mark.interop,
              pytest.mark.skipif(not shm_transport.supported(), reason="no memfd on this system")]

#: a minros subscriber checking 1080p images and saying which transport carried them
VIEWER = r'''
import sys, xmlrpc.client
import rospy
from sensor_msgs.msg import Image
topic = sys.argv[1]
rospy.init_node("viewer", anonymous=True)
seen = {"n": 0, "bad": 0}
def on_image(msg):
    data = msg.data
    if len(data) != 1920 * 1080 * 3 or data[0] != data[-1]:
        seen["bad"] += 1
    seen["n"] += 1
    info = xmlrpc.client.ServerProxy(rospy.get_node_uri()).getBusInfo("/viewer")[2]
    kinds = ",".join(sorted(c[3] for c in info if c[4] == topic))
    print("got", seen["n"], "bad", seen["bad"], "type", type(data).__name__, "transport", kinds,
          flush=True)
rospy.Subscriber(topic, Image, on_image, queue_size=2)
print("subscribed", flush=True)
rospy.spin()
'''


@pytest.fixture(scope="module")
def roscpp_node(tmp_path_factory) -> Path:
    return build_roscpp(NODE_CPP, "pubsub_node", tmp_path_factory.mktemp("roscpp"),
                        ("roscpp", "std_msgs", "geometry_msgs", "sensor_msgs"))


@pytest.fixture
def scripts(tmp_path: Path):
    require_reference()
    paths = {"talker": tmp_path / "talker.py", "listener": tmp_path / "listener.py",
             "viewer": tmp_path / "viewer.py"}
    paths["talker"].write_text(TALKER)
    paths["listener"].write_text(LISTENER)
    paths["viewer"].write_text(VIEWER)
    return paths


def _reference(impl: str, scripts, binary: Path, role: str, args, port: int, home: Path) -> Proc:
    env = reference_env(ros_env(port, home))
    if impl == "roscpp":
        return Proc([str(binary), role, *map(str, args)], env)
    return Proc([REFERENCE_PYTHON, str(scripts[role]), *map(str, args)], env)


def _publisher_uri(port: int, topic: str) -> str:
    master = xmlrpc.client.ServerProxy(f"http://127.0.0.1:{port}/")

    def find():
        for name, nodes in master.getSystemState("/t")[2][0]:
            if name == topic and nodes:
                return master.lookupNode("/t", nodes[0])[2]
        return None
    return wait_until(find, 20, what=f"a publisher of {topic}")


@pytest.mark.smoke
@pytest.mark.parametrize("impl", ["rospy", "roscpp"])
def test_reference_publishers_answer_the_offer_with_tcpros(scripts, roscpp_node, debian_rosmaster,
                                                           ros_home, impl):
    pub = _reference(impl, scripts, roscpp_node, "talker", ["/latched_img", "image", 1, 10, 1],
                     debian_rosmaster, ros_home)
    try:
        pub.read_until("published latched", 30)
        uri = _publisher_uri(debian_rosmaster, "/latched_img")
        offer = [wire_shm.offer(shm_transport.boot_id()), ["TCPROS"]]
        code, _, answer = xmlrpc.client.ServerProxy(uri).requestTopic("/probe", "/latched_img", offer)
        assert code == 1 and answer[0] == "TCPROS" and isinstance(answer[2], int), answer
        # offered alone, it is refused as any protocol they do not know
        code, _, answer = xmlrpc.client.ServerProxy(uri).requestTopic("/probe", "/latched_img",
                                                                     offer[:1])
        assert code != 1 and not answer  # rospy answers [], roscpp 0
    finally:
        pub.stop()


@pytest.mark.parametrize("impl", ["rospy", "roscpp"])
def test_a_minros_subscriber_of_a_reference_publisher_gets_tcpros(scripts, roscpp_node,
                                                                  debian_rosmaster, ros_home, impl):
    viewer = Proc([PYTHON, str(scripts["viewer"]), "/t_image"], ros_env(debian_rosmaster, ros_home))
    pub = None
    try:
        viewer.read_until("subscribed", 20)
        pub = _reference(impl, scripts, roscpp_node, "talker", ["/t_image", "image", 20, 20, 0],
                         debian_rosmaster, ros_home)
        out = viewer.read_until("got 5 ", 40)
    finally:
        for proc in (pub, viewer):
            if proc is not None:
                proc.stop()
    line = [x for x in out.splitlines() if x.startswith("got 5 ")][0]
    assert "bad 0 type bytes transport TCPROS" in line, out
    assert "MINROSSHM" not in out  # no fallback line: the offer was simply not taken


@pytest.mark.parametrize("impl", ["rospy", "roscpp"])
def test_a_reference_subscriber_of_a_minros_publisher_gets_tcpros(scripts, roscpp_node,
                                                                  debian_rosmaster, ros_home, impl):
    sub = _reference(impl, scripts, roscpp_node, "listener", ["/t_image", "image", 5],
                     debian_rosmaster, ros_home)
    pub = None
    try:
        sub.read_until("subscribed", 30)
        pub = Proc([PYTHON, str(scripts["talker"]), "/t_image", "image", "100", "10", "0"],
                   ros_env(debian_rosmaster, ros_home))
        out = sub.read_until("got ", 60)
        uri = _publisher_uri(debian_rosmaster, "/t_image")  # asked while the subscriber is there
        info = [c for c in xmlrpc.client.ServerProxy(uri).getBusInfo("/t")[2] if c[4] == "/t_image"]
        out += sub.read_until("listener done 5", 60)
    finally:
        for proc in (pub, sub):
            if proc is not None:
                proc.stop()
    got = [x for x in out.splitlines() if x.startswith("got ")]
    assert len(got) == 5
    assert all(re.search(r"1920x1080 bgr8 len=6220800|6220800", x) for x in got), got
    assert [c[3] for c in info] == ["TCPROS"], info
