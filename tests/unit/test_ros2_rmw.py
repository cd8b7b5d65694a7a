"""rmw's pure parts: ROS 2 names and types on DDS, QoS profiles, ros_discovery_info's codec
and the graph tables; and two minros contexts talking in one process (in a network
namespace, as every DDS test: tests/ros2_support.py)."""

from __future__ import annotations

import math
import threading

import pytest

from minros.ros2.rmw import names
from minros.ros2.rmw.graph import (
    Graph,
    GraphError,
    NodeEntities,
    decode_participant_info,
    encode_participant_info,
)
from minros.ros2.rmw.qos import DEFAULT, LATCHED, SENSOR_DATA, QoSProfile, from_dds
from minros.ros2.rtps import discovery as d


@pytest.mark.parametrize("name, ns, node, want", [
    ("chatter", "/", None, "/chatter"),
    ("chatter", "/robot", None, "/robot/chatter"),
    ("/abs", "/robot", None, "/abs"),
    ("~/status", "/robot", "cam", "/robot/cam/status"),
    ("a//b/", "/", None, "/a/b"),
])
def test_names_resolve_as_rcl(name, ns, node, want):
    assert names.resolve(name, ns, node) == want


@pytest.mark.parametrize("bad", ["", "1abc", "a b", "/x/2y"])
def test_bad_names_are_refused(bad):
    with pytest.raises(names.NameError_):
        names.resolve(bad)


def test_topics_and_types_on_dds():
    assert names.topic_to_dds("/chatter") == "rt/chatter"
    assert names.service_topics("/add") == ("rq/addRequest", "rr/addReply")
    assert names.topic_to_dds("/x", avoid_ros_namespace_conventions=True) == "x"
    assert names.dds_to_topic("rt/a/b") == ("/a/b", "topic")
    assert names.dds_to_topic("rq/addRequest") == ("/add", "request")
    assert names.dds_to_topic("rr/addReply") == ("/add", "reply")
    assert names.dds_to_topic("ros_discovery_info") is None
    assert names.type_to_dds("std_msgs/msg/String") == "std_msgs::msg::dds_::String_"
    assert names.type_to_dds("std_msgs/String") == "std_msgs::msg::dds_::String_"
    assert names.service_types("std_srvs/srv/SetBool") == (
        "std_srvs::srv::dds_::SetBool_Request_", "std_srvs::srv::dds_::SetBool_Response_")
    assert names.dds_to_type("std_srvs::srv::dds_::SetBool_Response_") == "std_srvs/srv/SetBool"
    assert names.dds_to_type("sensor_msgs::msg::dds_::Image_") == "sensor_msgs/msg/Image"
    assert names.dds_to_type("Foo") is None
    assert names.type_hash_user_data("RIHS01_ab", "clientid=1;") == \
        b"typehash=RIHS01_ab;clientid=1;"


def test_qos_profiles_as_rclpy_names_them():
    assert DEFAULT.to_dds() == d.Qos(reliability=d.RELIABLE, durability=d.VOLATILE,
                                     history=d.KEEP_LAST, depth=10)
    assert SENSOR_DATA.to_dds().reliability == d.BEST_EFFORT and SENSOR_DATA.depth == 5
    assert LATCHED.to_dds().durability == d.TRANSIENT_LOCAL and LATCHED.depth == 1
    assert from_dds(LATCHED.to_dds()) == LATCHED
    assert from_dds(d.Qos(history=d.KEEP_LAST, depth=0)).depth >= 1
    with pytest.raises(ValueError, match="reliability"):
        QoSProfile(reliability="sometimes")
    assert QoSProfile(deadline=0.5).describe() == "RELIABLE, VOLATILE, KEEP_LAST 10, deadline 0.5 s"
    assert math.isinf(DEFAULT.deadline)


def test_participant_entities_info_round_trip_and_bounds():
    gid = bytes(range(16))
    nodes = [NodeEntities("/", "talker", [b"r" * 16], [b"w" * 16, b"x" * 16]),
             NodeEntities("/robot", "cam", [], [])]
    sample = encode_participant_info(gid, nodes)
    assert decode_participant_info(sample) == (gid, nodes)
    with pytest.raises(GraphError):
        decode_participant_info(sample[:-3])
    lying = sample[:20] + (10_000_000).to_bytes(4, "little") + sample[24:]
    with pytest.raises(GraphError, match="sequence of"):
        decode_participant_info(lying)


def test_the_graph_joins_nodes_and_endpoints():
    graph = Graph(lambda prefix: "Fast DDS")
    prefix = bytes(range(12))
    writer = d.EndpointData(prefix + bytes.fromhex("00001103"), "rt/chatter",
                            "std_msgs::msg::dds_::String_", user_data=b"typehash=RIHS01_x;")
    reader = d.EndpointData(prefix + bytes.fromhex("00001204"), "rq/addRequest",
                            "example_interfaces::srv::dds_::AddTwoInts_Request_")
    graph.add_endpoint(writer)
    graph.add_endpoint(reader)
    version = graph.version
    done = threading.Event()
    threading.Thread(target=lambda: (graph.wait_for_change(version, 5), done.set())).start()
    graph.set_participant_nodes(prefix + bytes.fromhex("000001c1"),
                                [NodeEntities("/", "talker", [reader.guid], [writer.guid])])
    assert done.wait(5)
    assert graph.node_names_and_namespaces() == [("talker", "/")]
    assert graph.topic_names_and_types() == {"/chatter": ["std_msgs/msg/String"]}
    assert graph.service_names_and_types() == {"/add": ["example_interfaces/srv/AddTwoInts"]}
    [info] = graph.endpoints("/chatter", "publisher")
    assert (info.node_name, info.type_hash, info.vendor) == ("talker", "RIHS01_x", "Fast DDS")
    assert graph.endpoints("/chatter", "subscription") == []
    graph.remove_participant(prefix)
    assert graph.node_names_and_namespaces() == [] and graph.topic_names_and_types() == {}
    assert graph.wait_until(lambda g: not g.endpoints("/chatter"), 1)


def test_two_minros_contexts_pubsub_and_a_service():
    """minros to minros (no peer of another vendor): the same code paths, in one process."""
    from ros2_support import (
        Netns,
        cdr_setbool_request,
        cdr_setbool_response,
        cdr_string,
        context,
        read_setbool_response,
        read_string,
        require_netns,
    )

    require_netns()
    ns = Netns()
    a = b = None
    try:
        a, b = context(ns), context(ns)
        na, nb = a.create_node("a"), b.create_node("b", "/robot")
        got = []
        done = threading.Event()

        def on_message(payload, info):
            got.append(read_string(bytes(payload)))
            if len(got) == 100:
                done.set()
        nb.create_subscription("/chat", "std_msgs/msg/String", on_message)
        pub = na.create_publisher("chat", "std_msgs/msg/String", QoSProfile(depth=100))
        assert pub.wait_for_subscriptions(1, 10)
        for i in range(100):
            pub.publish(cdr_string(f"m{i}"))
        assert done.wait(10) and got == [f"m{i}" for i in range(100)]
        nb.create_service("set", "std_srvs/srv/SetBool",
                          lambda req: cdr_setbool_response(bool(req[4]), "b"))
        client = na.create_client("/robot/set", "std_srvs/srv/SetBool")
        assert client.wait_for_service(10)
        assert read_setbool_response(client.call(cdr_setbool_request(True), 5)) == (True, "b")
        assert a.graph.wait_until(lambda g: ("b", "/robot") in g.node_names_and_namespaces(), 5)
        assert ("/robot/set", ["std_srvs/srv/SetBool"]) in a.get_service_names_and_types()
    finally:
        for ctx in (a, b):
            if ctx is not None:
                ctx.shutdown()
        ns.delete()
