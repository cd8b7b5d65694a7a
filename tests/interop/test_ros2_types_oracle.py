"""minros's ROS 2 types against the real ROS 2 from PyPI: rclpy's serialize_message and
deserialize_message, and rosidl's own type hash generator, each run in one process per batch
(the pip ROS 2 of scripts/install-ros2-reference.sh: Jazzy and Kilted)."""

from __future__ import annotations

import io
from pathlib import Path

import pytest

from minros.msgs import get_message_class
from minros.msgs.testing import strategy_for as ros1_strategy
from minros.ros2.types import Mapper, TypeRegistry, registry
from minros.ros2.types.registry import SHARE
from minros.ros2.types.testing import (
    ROS2_HOME,
    oracle_available,
    plain,
    rclpy_check,
    ros2_plain_of_ros1,
    rosidl_hashes,
    samples,
    strategy_for,
)
from support import need

pytestmark = pytest.mark.interop

FIXTURES = Path(__file__).resolve().parent.parent / "unit" / "ros2_fixtures"
#: a bag's own ROS 1 definitions (the types of tests/unit/test_ros2_types_mapping.py)
BAG_DEFINITION = (Path(__file__).resolve().parent.parent / "unit" / "ros2_fixtures"
                  / "my_robot_msgs_Status.txt").read_text()
DISTROS = ["jazzy", "kilted"]


def require(distro: str) -> None:
    need(oracle_available(distro), f"the pip ROS 2 {distro} is not installed",
         "scripts/install-ros2-reference.sh")


def wheel_types(distro: str) -> list:
    """Every message type and service part the wheels ship."""
    reg = registry(distro)
    share = ROS2_HOME / distro / "share"
    names = [n for n in reg.type_names("msg")
             if (share / n.split("/")[0] / "msg" / (n.split("/")[2] + ".msg")).exists()]
    for service in reg.type_names("srv"):
        pkg, _, short = service.split("/")
        if (share / pkg / "srv" / f"{short}.srv").exists():
            names += [f"{service}_{part}" for part in ("Request", "Response", "Event")]
    return names


def ros1_bytes(msg) -> bytes:
    buf = io.BytesIO()
    msg.serialize(buf)
    return buf.getvalue()


@pytest.mark.parametrize("distro", DISTROS)
def test_rclpy_reads_what_minros_writes_and_the_other_way(distro):
    """For every type the wheels ship: rclpy decodes our CDR (hypothesis samples) to the same
    values; we decode rclpy's serialize_message bytes of them to the same values; our default
    message equals rclpy's. And every ROS 1 type both sides ship: rclpy decodes what the
    ROS 1 -> CDR converter writes to what the ROS 1 message said, and the CDR -> ROS 1
    converter turns rclpy's bytes back into the ROS 1 message. One rclpy process."""
    require(distro)
    reg = registry(distro)
    names = wheel_types(distro)
    assert len(names) > 220
    requests, expected = [], []
    for name in names:
        codec = reg.codec(name)
        requests.append((name, None))
        expected.append(("default", name, plain(reg, name, codec.cls())))
        for value in samples(strategy_for(reg, name), 3):
            requests.append((name, codec.serialize(value)))
            expected.append(("value", name, plain(reg, name, value)))
    mapper = Mapper(distro)
    bridged = 0
    for ros1_type in sorted({t for t in _ros1_types() if not mapper.message(t).generated}):
        m = mapper.message(ros1_type)
        if m.ros2_type not in names:
            continue
        bridged += 1
        for msg in samples(ros1_strategy(ros1_type), 2):
            requests.append((m.ros2_type, m.transcoder.ros1_to_cdr(ros1_bytes(msg))))
            expected.append(("bridged", ros1_type, (msg, ros2_plain_of_ros1(m, msg))))
    assert bridged > 100

    results = rclpy_check(distro, requests)
    assert len(results) == len(requests)
    for (kind, name, want), (ros2_type, _data), got in zip(expected, requests, results):
        assert "error" not in got, (name, got.get("error"))
        theirs = bytes.fromhex(got["hex"])
        if kind == "bridged":
            msg, values = want
            # ROS 1 strings may hold NUL: the converters carry the bytes, but ROS 2's
            # strings are C strings and rclpy cuts them there (ROS 2 cannot carry those)
            assert got["plain"] == c_strings(values), name
            m = mapper.message(name)
            back = get_message_class(name)().deserialize(
                m.transcoder.cdr_to_ros1(theirs, seq=getattr(getattr(msg, "header", None),
                                                             "seq", 0)))
            assert ros2_plain_of_ros1(m, back) == c_strings(values), name
            continue
        assert got["plain"] == want, (kind, name)
        assert plain(reg, ros2_type, reg.codec(ros2_type).deserialize(theirs)) == want, name


def c_strings(value):
    if isinstance(value, dict):
        return {k: c_strings(v) for k, v in value.items()}
    if isinstance(value, list):
        return [c_strings(v) for v in value]
    if isinstance(value, str):
        return value.split("\0", 1)[0]
    return value


def _ros1_types() -> list:
    from minros.msgs.registry import list_types

    out = []
    for package in {n.split("/")[0] for n in registry().type_names("msg")} | {"tf", "uuid_msgs"}:
        try:
            out += list_types(package)
        except LookupError:
            pass
    return out


def _files(folder: Path) -> list:
    return [(p.parent.name, p.stem, p.read_text()) for kind in ("msg", "srv", "action")
            for p in sorted(folder.glob(f"{kind}/*.{kind}"))]


@pytest.mark.parametrize("distro", DISTROS)
def test_rosidl_computes_the_same_hashes(distro):
    """rosidl_adapter + rosidl_generator_type_description (the wheels' own) on ROS 2's
    test_interface_files, tf2_msgs and turtlesim (actions included), and on ROS 2 types minros
    made from ROS 1 definitions: every hash and full description equals ours."""
    require(distro)
    mapper = Mapper(distro)
    mapper.add_ros1_definition("my_robot_msgs/Status", BAG_DEFINITION)
    mapper.message("my_robot_msgs/Status")
    mapper.message("rosgraph_msgs/TopicStatistics")
    mapper.service("roscpp/GetLoggers")
    mapper.action("actionlib_tutorials/Fibonacci")
    made = {}
    for name in ("my_robot_msgs/msg/Wheel", "my_robot_msgs/msg/Status",
                 "rosgraph_msgs/msg/TopicStatistics", "roscpp/msg/Logger"):
        struct = mapper.ros2.message(name)
        made.setdefault(struct.package, []).append(("msg", struct.short_name, struct.text))
    service = mapper.ros2.service("roscpp/srv/GetLoggers")
    made["roscpp"].append(("srv", "GetLoggers", service.request.text + "---\n"
                           + service.response.text))
    action = mapper.ros2.action("actionlib_tutorials/action/Fibonacci")
    made["actionlib_tutorials"] = [("action", "Fibonacci", "---\n".join(
        part.text for part in (action.goal, action.result, action.feedback)))]
    packages = {"test_interface_files": _files(FIXTURES / "test_interface_files"),
                "tf2_msgs": _files(SHARE / distro / "tf2_msgs"),
                "turtlesim": _files(SHARE / distro / "turtlesim"), **made}
    theirs = rosidl_hashes(distro, packages)
    ours = TypeRegistry(distro, paths=[FIXTURES], parent=mapper.ros2)
    hashes = {k: v for k, v in theirs.items() if not k.startswith("description:")}
    assert len(hashes) > 120
    for name, digest in hashes.items():
        assert ours.type_hash(name) == digest, name
    for key, description in theirs.items():
        if key.startswith("description:"):
            assert ours.type_description(key[len("description:"):]) == description, key
    assert "my_robot_msgs/msg/Status" in hashes and "tf2_msgs/action/LookupTransform" in hashes
