"""RIHS01 type hashes and type descriptions (minros.ros2.types.hashing), against the golden
vectors of the ROS 2 spec and every hash the pip ROS 2 ships."""

from __future__ import annotations

import json

import pytest

from minros.ros2 import types
from minros.ros2.types import TypeRegistry, dds_type_name, from_dds_type_name
from minros.ros2.types.testing import ROS2_HOME
from support import need

#: ../shared/spec/ros2.md section 1g (the pip ROS 2's JSON), verbatim
GOLDEN = {
    "std_msgs/msg/String": "df668c740482bbd48fb39d76a70dfd4bd59db1288021743503259e948f6b1a18",
    "builtin_interfaces/msg/Time":
        "b106235e25a4c5ed35098aa0a61a3ee9c9b18d197f398b0e4206cea9acf9c197",
    "std_msgs/msg/Header": "f49fb3ae2cf070f793645ff749683ac6b06203e41c891e17701b1cb597ce6a01",
    "geometry_msgs/msg/Twist":
        "9c45bf16fe0983d80e3cfe750d6835843d265a9a6c46bd2e609fcddde6fb8d2a",
    "sensor_msgs/msg/Image": "d31d41a9a4c4bc8eae9be757b0beed306564f7526c88ea6a4588fb9582527d47",
    "sensor_msgs/msg/PointCloud2":
        "9198cabf7da3796ae6fe19c4cb3bdd3525492988c70522628af5daa124bae2b5",
    "sensor_msgs/msg/LaserScan":
        "64c191398013af96509d518dac71d5164f9382553fce5c1f8cca5be7924bd828",
    "rmw_dds_common/msg/ParticipantEntitiesInfo":
        "91a0593bacdcc50ea9bdcf849a938b128412cc1ea821245c663bcd26f83c295e",
}


@pytest.mark.parametrize("distro", ["jazzy", "kilted"])
def test_golden_vectors(distro):
    for name, digest in GOLDEN.items():
        assert types.type_hash(name, distro) == "RIHS01_" + digest, name


@pytest.mark.parametrize("distro", ["jazzy", "kilted"])
def test_every_hash_and_description_the_pip_ros2_ships(distro):
    share = ROS2_HOME / distro / "share"
    need(share.is_dir(), f"the pip ROS 2 {distro} is not installed",
         "scripts/install-ros2-reference.sh")
    reg = TypeRegistry(distro)
    files = sorted(p for kind in ("msg", "srv", "action") for p in share.glob(f"*/{kind}/*.json"))
    checked = set()
    for path in files:
        data = json.loads(path.read_text())
        top = data["type_description_msg"]["type_description"]["type_name"]
        # the whole description, default values included, as rosidl wrote it
        assert reg.type_description(top) == data["type_description_msg"], path
        for entry in data["type_hashes"]:
            assert reg.type_hash(entry["type_name"]) == entry["hash_string"], entry["type_name"]
            checked.add(entry["type_name"])
    # every message and service of the wheels, with services' Request/Response/Event
    assert len(files) > 180 and len(checked) > 250
    assert {"std_srvs/srv/SetBool", "std_srvs/srv/SetBool_Event",
            "service_msgs/msg/ServiceEventInfo"} <= checked


def test_humble_has_none():
    reg = TypeRegistry("humble")
    assert not reg.has_type_hashes
    with pytest.raises(ValueError, match="REP-2011 came with Iron"):
        reg.type_hash("std_msgs/msg/String")
    assert reg.service("std_srvs/srv/SetBool").event is None


def test_defaults_do_not_change_the_hash_and_constants_neither():
    reg = TypeRegistry("jazzy").child()
    reg.add_definition("msg", "a/msg/T", "int32 x\nstring s\n")
    plain = reg.type_hash("a/msg/T")
    reg.add_definition("msg", "a/msg/T", "# comment\nint32 X_MAX=3\nint32 x 7\nstring s 'hi'\n")
    assert reg.type_hash("a/msg/T") == plain
    assert reg.type_description("a/msg/T")["type_description"]["fields"][0]["default_value"] == "7"
    reg.add_definition("msg", "a/msg/T", "int64 x\nstring s\n")
    assert reg.type_hash("a/msg/T") != plain


def test_dds_type_names():
    assert dds_type_name("std_msgs/msg/String") == "std_msgs::msg::dds_::String_"
    assert dds_type_name("std_srvs/srv/SetBool_Request") == "std_srvs::srv::dds_::SetBool_Request_"
    assert dds_type_name("tf2_msgs/action/LookupTransform_FeedbackMessage") == \
        "tf2_msgs::action::dds_::LookupTransform_FeedbackMessage_"
    assert from_dds_type_name("rmw_dds_common::msg::dds_::ParticipantEntitiesInfo_") == \
        "rmw_dds_common/msg/ParticipantEntitiesInfo"
    with pytest.raises(ValueError, match="not a ROS 2 DDS type name"):
        from_dds_type_name("DCPSParticipant")
