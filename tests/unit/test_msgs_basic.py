"""Smoke tests of the message system: md5 sums, classes, round trips, stub imports."""

from __future__ import annotations

import io

import pytest

from minros.msgs import REGISTRY, UnknownTypeError, get_message_class, get_service_class


@pytest.mark.parametrize("type_name, md5", [
    ("std_msgs/String", "992ce8a1687cec8c8bd883ec73ca41d1"),
    ("std_msgs/Header", "2176decaecbce78abc3b96ef049fabed"),
    ("geometry_msgs/Twist", "9f195f881246fdfa2798d1d3eebca84a"),
    ("geometry_msgs/PoseStamped", "d3812c3cbc69362b77dc0b19b345f8f5"),
    ("rosgraph_msgs/Log", "acffd30cd6b6de30f120938c17c593fb"),
    ("rosgraph_msgs/Clock", "a9c97c1d230cfc112e270351a944ee47"),
    ("turtlesim/Pose", "863b248d5016ca62ea2e895ae5265cf9"),
    ("turtlesim/Color", "353891e354491c51aabe32df673fb446"),
    ("rospy_tutorials/Floats", "420cd38b6b071cd49f2970c3e2cee511"),
    ("rospy_tutorials/HeaderString", "c99a9440709e4d4a9716d55b8270d5e7"),
])
def test_message_md5(type_name: str, md5: str) -> None:
    assert get_message_class(type_name)._md5sum == md5


@pytest.mark.parametrize("type_name, md5", [
    ("std_srvs/Empty", "d41d8cd98f00b204e9800998ecf8427e"),
    ("rospy_tutorials/AddTwoInts", "6a2e34150c00229791cc89ff309fff21"),
    ("turtlesim/Spawn", "0b2d2e872a8e2887d5ed626f2bf2c561"),
    ("turtlesim/Kill", "c1f3d28f1b044c871e6eff2e9fc3c667"),
    ("turtlesim/SetPen", "9f452acce566bf0c0954594f69a8e41b"),
    ("turtlesim/TeleportAbsolute", "a130bc60ee6513855dc62ea83fcc5b20"),
    ("turtlesim/TeleportRelative", "9d5c2dcd348ac8f76ce2a4307bd63a13"),
])
def test_service_md5(type_name: str, md5: str) -> None:
    assert get_service_class(type_name)._md5sum == md5


def test_add_two_ints_parts() -> None:
    srv = get_service_class("rospy_tutorials/AddTwoInts")
    assert srv._request_class._md5sum == "36d09b846be0b371c5f190354dd3153e"
    assert srv._response_class._md5sum == "b88405221c77b1878a3cbbfff53428d7"
    assert srv._request_class._type == "rospy_tutorials/AddTwoIntsRequest"


def test_pose_full_text() -> None:
    assert get_message_class("turtlesim/Pose")._full_text == (
        "float32 x\nfloat32 y\nfloat32 theta\n\nfloat32 linear_velocity\nfloat32 angular_velocity")


def test_string_bytes_and_round_trip() -> None:
    from std_msgs.msg import String

    buf = io.BytesIO()
    String("héllo").serialize(buf)
    assert buf.getvalue() == b"\x06\x00\x00\x00h\xc3\xa9llo"
    assert String().deserialize(buf.getvalue()).data == "héllo"


def test_stub_imports() -> None:
    from geometry_msgs.msg import PoseStamped
    from std_srvs.srv import Empty, EmptyRequest, EmptyResponse

    assert Empty._request_class is EmptyRequest and Empty._response_class is EmptyResponse
    assert PoseStamped is REGISTRY.get_class("geometry_msgs/PoseStamped")
    assert PoseStamped._has_header


def test_unknown_type() -> None:
    with pytest.raises(UnknownTypeError, match="no_such_pkg"):
        get_message_class("no_such_pkg/Foo")
    with pytest.raises(UnknownTypeError, match="Nope"):
        get_message_class("std_msgs/Nope")
    with pytest.raises(ImportError):
        from std_msgs.msg import Nope  # noqa: F401


def test_concurrent_first_use_gives_one_class_per_type() -> None:
    import threading

    from minros.msgs import MsgContext

    ctx = MsgContext()
    names = ["visualization_msgs/MarkerArray", "nav_msgs/Odometry", "sensor_msgs/PointCloud2",
             "diagnostic_msgs/DiagnosticArray", "trajectory_msgs/JointTrajectory"]
    results: list = []
    errors: list = []
    start = threading.Barrier(6)

    def load() -> None:
        try:
            start.wait(5)
            results.append(tuple(ctx.get_class(n) for n in names))
        except Exception as exc:  # noqa: BLE001 - reported below
            errors.append(exc)

    threads = [threading.Thread(target=load) for _ in range(6)]
    for t in threads:
        t.start()
    for t in threads:
        t.join(30)
    assert not errors and len(results) == 6
    assert all(r == results[0] for r in results)
