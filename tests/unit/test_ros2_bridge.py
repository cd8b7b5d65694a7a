"""The bridge's pure parts: parameter_bridge's configuration, the QoS rules, the plan
(dynamic_bridge's rules against fake graphs), the type book over the real mapper, and the
service handler that declines to answer."""

from __future__ import annotations

import io
import math
import threading

import pytest

from minros.ros2.bridge import config as cfg
from minros.ros2.bridge.plan import (
    ONE_TO_TWO,
    TWO_TO_ONE,
    Options,
    Ros1Graph,
    Ros2Graph,
    Ros2Topic,
    ServiceBridge,
    TopicBridge,
    Unknown,
    Unmapped,
    plan,
)
from minros.ros2.bridge.qos import TF_STATIC_DEPTH, latches, publisher_qos, subscription_qos
from minros.ros2.bridge.raw import raw_class, raw_service_class
from minros.ros2.rmw.qos import QoSProfile

RELIABLE = QoSProfile()
BEST_EFFORT = QoSProfile(reliability="best_effort", depth=5)
LATCHED = QoSProfile(depth=1, durability="transient_local")


# -- configuration ---------------------------------------------------------------------------

README_EXAMPLE = """
topics:
  -
    topic: /chatter  # Topic name on both ROS 1 and ROS 2
    type: std_msgs/msg/String  # Type of topic to bridge
    queue_size: 1  # Queue size
  -
    topic: /tf_static
    type: tf2_msgs/msg/TFMessage
    queue_size: 1
    qos:
      history: keep_all
      durability: transient_local
  -
    topic: /some_ros1_topic
    type: std_msgs/msg/String
    queue_size: 1
    qos:
      history: keep_last  # OR keep_all, then you can omit `depth` parameter below
      depth: 10  # Only required when history == keep_last
      reliability: reliable  # OR best_effort
      durability: transient_local  # OR volatile
      deadline:
          secs: 10
          nsecs: 2345
      lifespan:
          secs: 20
          nsecs: 3456
      liveliness: liveliness_system_default
      liveliness_lease_duration:
          secs: 40
          nsecs: 5678
services_2_to_1:
  -
    service: /add_two_ints  # ROS 1 service name
    type: roscpp_tutorials/TwoInts  # The ROS 1 service type name
services_1_to_2:
  - {service: set_it, type: std_srvs/srv/SetBool}
  - {service: /old_form, package: std_srvs, type: Trigger}
"""


def test_config_reads_ros1_bridges_readme_examples(tmp_path):
    path = tmp_path / "bridge.yaml"
    path.write_text(README_EXAMPLE)
    config = cfg.load(str(path))
    chatter, tf_static, some = config.topics
    assert chatter == cfg.TopicConfig("/chatter", "std_msgs/msg/String", 1, None)
    assert tf_static.qos == QoSProfile(history="keep_all", durability="transient_local")
    assert some.qos == QoSProfile(depth=10, durability="transient_local",
                                  deadline=10.000002345, lifespan=20.000003456,
                                  liveliness_lease_duration=40.000005678)
    assert config.services_2_to_1 == [cfg.ServiceConfig("/add_two_ints",
                                                        "roscpp_tutorials/TwoInts")]
    assert config.services_1_to_2 == [cfg.ServiceConfig("/set_it", "std_srvs/srv/SetBool"),
                                      cfg.ServiceConfig("/old_form", "std_srvs/srv/Trigger")]


def test_config_defaults_and_ros1_type_spellings():
    config = cfg.parse({"topics": [{"topic": "a", "type": "std_msgs/String"}],
                        "services_2_to_1": [{"service": "/s", "type": "std_srvs/srv/Empty"}]})
    assert config.topics == [cfg.TopicConfig("/a", "std_msgs/msg/String", 100, None)]
    assert config.services_2_to_1 == [cfg.ServiceConfig("/s", "std_srvs/Empty")]
    assert not cfg.parse(None) and not cfg.parse({"topics": []})
    assert cfg.parse_qos({"liveliness": 3}, "q").liveliness == "manual_by_topic"
    assert cfg.parse_qos({"liveliness": "LIVELINESS_AUTOMATIC"}, "q").liveliness == "automatic"
    assert cfg.parse_qos({"deadline": {"secs": 0, "nsecs": 0}}, "q").deadline == math.inf


@pytest.mark.parametrize("document, says", [
    ([1], "expected a mapping with the keys topics"),
    ({"topic": []}, "unknown key 'topic'"),
    ({"topics": {"topic": "/a"}}, "topics must be a list"),
    ({"topics": [{"type": "std_msgs/msg/String"}]}, "topics[0]: needs topic"),
    ({"topics": [{"topic": "/a"}]}, "topics[0] (/a): needs type"),
    ({"topics": [{"topic": "/a", "type": "String"}]}, "needs type: a type such as"),
    ({"topics": [{"topic": "/a", "type": "std_srvs/srv/SetBool"}]}, "is not a msg type"),
    ({"topics": [{"topic": "/a", "type": "std_msgs/String", "queue_size": -1}]}, "queue_size"),
    ({"topics": [{"topic": "/a", "type": "std_msgs/String", "qos": {"depth": 3}}]},
     "depth without history"),
    ({"topics": [{"topic": "/a", "type": "std_msgs/String", "qos": {"history": "keep_last"}}]},
     "keep_last needs depth"),
    ({"topics": [{"topic": "/a", "type": "std_msgs/String", "qos": {"reliability": "yes"}}]},
     "reliability 'yes': reliable or best_effort"),
    ({"topics": [{"topic": "/a", "type": "std_msgs/String", "qos": {"deadline": 5}}]},
     "expected {secs: S, nsecs: N}"),
    ({"topics": [{"topic": "/a", "type": "std_msgs/String", "qos": {"liveliness": "x"}}]},
     "LIVELINESS_SYSTEM_DEFAULT"),
    ({"topics": [{"topic": "/a", "type": "std_msgs/String", "qos": {"durable": 1}}]},
     "unknown policy 'durable'"),
    ({"topics": [{"topic": "/a", "type": "std_msgs/String"}] * 2}, "listed twice"),
    ({"services_1_to_2": [{"service": "/s", "type": "std_srvs/srv/Empty"}],
      "services_2_to_1": [{"service": "/s", "type": "std_srvs/Empty"}]}, "in both"),
    ({"services_1_to_2": [{"service": "/s", "type": "std_srvs/msg/Empty"}]}, "not a srv type"),
])
def test_config_mistakes_name_the_entry_and_the_fix(document, says):
    with pytest.raises(cfg.ConfigError) as caught:
        cfg.parse(document, "bridge.yaml")
    assert says in str(caught.value) and str(caught.value).startswith("bridge.yaml")


def test_config_files_that_cannot_be_read(tmp_path):
    with pytest.raises(cfg.ConfigError, match="cannot read"):
        cfg.load(str(tmp_path / "absent.yaml"))
    bad = tmp_path / "bad.yaml"
    bad.write_text("topics: [\n")
    with pytest.raises(cfg.ConfigError, match="is not YAML"):
        cfg.load(str(bad))


# -- QoS ---------------------------------------------------------------------------------------

def test_qos_rules():
    assert publisher_qos("/chatter", False, 10) == QoSProfile(depth=10)
    assert publisher_qos("/map", True, 10) == LATCHED
    assert publisher_qos("/tf_static", True, 10).depth == TF_STATIC_DEPTH
    explicit = QoSProfile(reliability="best_effort")
    assert publisher_qos("/x", True, 10, explicit) is explicit
    # a subscription matches every publisher: the weakest offer of each policy
    assert subscription_qos([], 7) == QoSProfile(depth=7)
    assert subscription_qos([RELIABLE, BEST_EFFORT], 10).reliability == "best_effort"
    assert subscription_qos([LATCHED], 10).durability == "transient_local"
    assert subscription_qos([LATCHED, RELIABLE], 10).durability == "volatile"
    assert subscription_qos([BEST_EFFORT], 3, explicit) is explicit
    assert latches(LATCHED) and not latches(RELIABLE)


# -- the plan -------------------------------------------------------------------------------

class FakeTypes:
    """std_msgs/String <-> std_msgs/msg/String and friends; my_msgs/Secret not installed."""

    messages = {"std_msgs/String": "std_msgs/msg/String", "std_msgs/Int32": "std_msgs/msg/Int32"}
    services = {"std_srvs/SetBool": "std_srvs/srv/SetBool",
                "roscpp/GetLoggers": "roscpp/srv/GetLoggers"}

    def ros2_for_ros1(self, t):
        if t == "my_msgs/Secret":
            raise Unknown(t)
        if t not in self.messages:
            raise Unmapped("has no mapping")
        return self.messages[t]

    def ros1_for_ros2(self, t):
        for k, v in self.messages.items():
            if v == t:
                return k
        raise Unmapped("is not known here")

    def ros2_service_for_ros1(self, t):
        if t not in self.services:
            raise Unmapped("has no mapping")
        return self.services[t]

    def ros1_service_for_ros2(self, t):
        for k, v in self.services.items():
            if v == t:
                return k
        raise Unmapped("has no ROS 1 counterpart")


def topic(types, qos=()):
    return Ros2Topic(tuple(types), tuple(qos))


def test_plan_bridges_a_topic_where_one_side_publishes_and_the_other_subscribes():
    ros1 = Ros1Graph(publishers={"/chatter": "std_msgs/String", "/alone": "std_msgs/String"},
                     subscribers={"/cmd": "std_msgs/Int32"})
    ros2 = Ros2Graph(publishers={"/cmd": topic(["std_msgs/msg/Int32"], [BEST_EFFORT]),
                                 "/unheard": topic(["std_msgs/msg/Int32"])},
                     subscribers={"/chatter": topic(["std_msgs/msg/String"])})
    p = plan(ros1, ros2, Options(), FakeTypes())
    assert p.topics == {
        ("/chatter", ONE_TO_TWO): TopicBridge("/chatter", ONE_TO_TWO, "std_msgs/String",
                                              "std_msgs/msg/String", 10),
        ("/cmd", TWO_TO_ONE): TopicBridge("/cmd", TWO_TO_ONE, "std_msgs/Int32",
                                          "std_msgs/msg/Int32", 10,
                                          QoSProfile(reliability="best_effort", depth=10)),
    }
    assert p.problems == {}
    # --bridge-all-*: whether or not the other side listens
    every = plan(ros1, ros2, Options(bridge_all_1to2=True, bridge_all_2to1=True), FakeTypes())
    assert set(every.topics) == {("/chatter", ONE_TO_TWO), ("/alone", ONE_TO_TWO),
                                 ("/cmd", TWO_TO_ONE), ("/unheard", TWO_TO_ONE)}


def test_plan_leaves_out_mismatched_types_and_says_why():
    ros1 = Ros1Graph(publishers={"/a": "std_msgs/String", "/b": "geometry_msgs/Nope",
                                 "/c": "std_msgs/String"},
                     subscribers={"/d": "std_msgs/String"})
    ros2 = Ros2Graph(subscribers={"/a": topic(["std_msgs/msg/Int32"]),
                                  "/b": topic(["geometry_msgs/msg/Nope"]),
                                  "/c": topic(["std_msgs/msg/String", "std_msgs/msg/Int32"])},
                     publishers={"/d": topic(["std_msgs/msg/Int32"]),
                                 "/e": topic(["foo/msg/Bar"])})
    p = plan(ros1, ros2, Options(bridge_all_2to1=True), FakeTypes())
    assert p.topics == {}
    texts = sorted(p.problems.values())
    assert any("ROS 1 publishes std_msgs/String, which maps to std_msgs/msg/String, and ROS 2 "
               "subscribes to std_msgs/msg/Int32" in t for t in texts)
    assert any("/b is not bridged to ROS 2: geometry_msgs/Nope has no mapping" in t for t in texts)
    assert any("several types" in t for t in texts)
    assert any("ROS 2 publishes std_msgs/msg/Int32" in t and "subscribes to std_msgs/String" in t
               for t in texts)
    assert any("/e is not bridged to ROS 1: foo/msg/Bar is not known here" in t for t in texts)
    # a key per fault: the same graph gives the same keys (the bridge says each once)
    assert plan(ros1, ros2, Options(bridge_all_2to1=True), FakeTypes()).problems == p.problems


def test_plan_takes_an_uninstalled_ros1_type_as_the_ros2_subscriber_asks():
    ros1 = Ros1Graph(publishers={"/s": "my_msgs/Secret"})
    ros2 = Ros2Graph(subscribers={"/s": topic(["my_msgs/msg/Secret"])})
    assert plan(ros1, ros2, Options(), FakeTypes()).topics[("/s", ONE_TO_TWO)].ros2_type == \
        "my_msgs/msg/Secret"
    # bridged to everyone: the publisher's connection header decides
    alone = plan(Ros1Graph(publishers={"/s": "my_msgs/Secret"}), Ros2Graph(),
                 Options(bridge_all_1to2=True), FakeTypes())
    assert alone.topics[("/s", ONE_TO_TWO)].ros2_type is None


def test_plan_services_both_ways_and_what_it_leaves_out():
    ros1 = Ros1Graph(services={"/ros1_set": "std_srvs/SetBool", "/both": "std_srvs/SetBool",
                               "/talker/get_loggers": "roscpp/GetLoggers",
                               "/odd": "roscpp/GetLoggers"})
    ros2 = Ros2Graph(services={"/rclpy_set": ("std_srvs/srv/SetBool",),
                               "/both": ("std_srvs/srv/SetBool",),
                               "/node/list_parameters": ("rcl_interfaces/srv/ListParameters",)})
    p = plan(ros1, ros2, Options(), FakeTypes())
    assert p.services == {
        "/ros1_set": ServiceBridge("/ros1_set", TWO_TO_ONE, "std_srvs/SetBool",
                                   "std_srvs/srv/SetBool"),
        "/rclpy_set": ServiceBridge("/rclpy_set", ONE_TO_TWO, "std_srvs/SetBool",
                                    "std_srvs/srv/SetBool"),
    }
    assert list(p.problems.values()) == [
        "service /both is not bridged: it has servers in ROS 1 and in ROS 2 (a call would "
        "reach two servers)"]


def test_plan_leaves_out_rosout_and_parameter_events():
    ros1 = Ros1Graph(publishers={"/rosout": "rosgraph_msgs/Log"},
                     subscribers={"/rosout": "rosgraph_msgs/Log"})
    ros2 = Ros2Graph(publishers={"/rosout": topic(["rcl_interfaces/msg/Log"]),
                                 "/parameter_events": topic(["rcl_interfaces/msg/Foo"])},
                     subscribers={"/rosout": topic(["rcl_interfaces/msg/Log"])})
    p = plan(ros1, ros2, Options(bridge_all_1to2=True, bridge_all_2to1=True), FakeTypes())
    assert p.topics == {} and p.problems == {}


def test_plan_with_a_configuration_bridges_exactly_what_it_lists():
    config = cfg.parse({"topics": [{"topic": "/chatter", "type": "std_msgs/msg/String",
                                    "queue_size": 5},
                                   {"topic": "/latched", "type": "std_msgs/msg/Int32",
                                    "qos": {"durability": "transient_local"}},
                                   {"topic": "/unknown", "type": "foo/msg/Bar"}],
                        "services_2_to_1": [{"service": "/a", "type": "std_srvs/SetBool"}],
                        "services_1_to_2": [{"service": "/b", "type": "std_srvs/srv/SetBool"}]})
    ros1 = Ros1Graph(publishers={"/other": "std_msgs/String"})
    ros2 = Ros2Graph(subscribers={"/other": topic(["std_msgs/msg/String"])},
                     publishers={"/chatter": topic(["std_msgs/msg/String"], [BEST_EFFORT])})
    p = plan(ros1, ros2, Options(config=config), FakeTypes())
    assert p.topics[("/chatter", ONE_TO_TWO)] == TopicBridge(
        "/chatter", ONE_TO_TWO, "std_msgs/String", "std_msgs/msg/String", 5, None, True)
    # without qos: the subscription matches the publishers there are
    assert p.topics[("/chatter", TWO_TO_ONE)].qos == QoSProfile(reliability="best_effort",
                                                                depth=5)
    latched = QoSProfile(depth=10, durability="transient_local")
    assert p.topics[("/latched", ONE_TO_TWO)].qos == latched
    assert p.topics[("/latched", TWO_TO_ONE)].qos == latched
    assert ("/other", ONE_TO_TWO) not in p.topics
    assert set(p.services) == {"/a", "/b"}
    assert list(p.problems.values()) == ["/unknown is not bridged: foo/msg/Bar is not known here"]


# -- the type book over the real mapper --------------------------------------------------------

def test_type_book_over_the_mapper():
    from minros.msgs import get_message_class
    from minros.ros2.bridge.runtime import TypeBook

    book = TypeBook("jazzy")
    assert book.ros2_for_ros1("sensor_msgs/CameraInfo") == "sensor_msgs/msg/CameraInfo"
    assert book.ros1_for_ros2("std_msgs/msg/String") == "std_msgs/String"
    assert book.ros1_for_ros2("rcl_interfaces/msg/Log") == "rosgraph_msgs/Log"
    assert book.ros2_service_for_ros1("std_srvs/SetBool") == "std_srvs/srv/SetBool"
    assert book.ros1_service_for_ros2("std_srvs/srv/Trigger") == "std_srvs/Trigger"
    with pytest.raises(Unknown):
        book.ros2_for_ros1("my_robot_msgs/Status")
    with pytest.raises(Unmapped, match="not known here"):
        book.ros1_for_ros2("foo_msgs/msg/Bar")
    with pytest.raises(Unmapped, match="no ROS 1 counterpart"):
        book.ros1_service_for_ros2("foo_msgs/srv/Bar")
    assert book.ros1_md5("std_msgs/String") == get_message_class("std_msgs/String")._md5sum
    from minros.msgs import get_service_class

    assert book.ros1_srv_md5("std_srvs/SetBool") == get_service_class("std_srvs/SetBool")._md5sum


def test_type_book_learns_a_type_from_a_connection_header():
    from pathlib import Path

    from minros.msgs import generate_dynamic
    from minros.ros2.bridge.runtime import TypeBook

    text = (Path(__file__).parent / "ros2_fixtures" / "my_robot_msgs_Status.txt").read_text()
    md5 = generate_dynamic("my_robot_msgs/Status", text)["my_robot_msgs/Status"]._md5sum
    book = TypeBook("jazzy")
    mapping = book.learn("my_robot_msgs/Status", md5, text)
    assert (mapping.ros2_type, mapping.generated) == ("my_robot_msgs/msg/Status", True)
    assert book.generation == 1  # the plan is made again: the type is known now
    assert book.ros1_for_ros2("my_robot_msgs/msg/Status") == "my_robot_msgs/Status"
    assert book.ros1_md5("my_robot_msgs/Status") == md5
    with pytest.raises(Unmapped, match="its message_definition gives"):
        book.learn("my_robot_msgs/Wheel", "0" * 32, "string Name\nfloat32 speed\n")
    with pytest.raises(Unmapped, match="no message_definition"):
        book.learn("other_msgs/Thing", "1" * 32, "")
    # an installed type under its own md5sum is the installed mapping
    from minros.msgs import get_message_class

    string = get_message_class("std_msgs/String")
    assert book.learn("std_msgs/String", string._md5sum, "").ros2_type == "std_msgs/msg/String"


def test_raw_classes_carry_bytes():
    cls = raw_class("std_msgs/String", "992ce8a1687cec8c8bd883ec73ca41d1", "string data\n")
    assert cls is raw_class("std_msgs/String", "992ce8a1687cec8c8bd883ec73ca41d1",
                            "string data\n")
    msg = cls().deserialize(b"\x02\x00\x00\x00hi")
    out = io.BytesIO()
    msg.serialize(out)
    assert out.getvalue() == b"\x02\x00\x00\x00hi" and not cls._keeps_buffer
    srv = raw_service_class("std_srvs/SetBool", "09fb03525b03e7ea1fd3992bafd87e16")
    assert srv._request_class._type == "std_srvs/SetBoolRequest"
    assert srv is raw_service_class("std_srvs/SetBool", "09fb03525b03e7ea1fd3992bafd87e16")


def test_once_log_says_each_fault_once_and_is_bounded(monkeypatch):
    from minros.ros2.bridge import runtime

    said = []
    once = runtime.OnceLog(said.append)
    assert once("a", "first") and not once("a", "again")
    monkeypatch.setattr(runtime, "MAX_SAID", 3)
    for i in range(10):
        once(f"k{i}", f"line {i}")
    assert said == ["first", "line 0", "line 1",
                    "more than 3 distinct problems: the rest are not shown"]


def test_a_service_handler_may_decline_to_answer():
    """rmw's Service sends no reply when its handler returns None (the bridge's, when the ROS
    1 server failed): the client times out, and nothing is logged as a failure."""
    import logging

    from minros.ros2.rmw import ServiceTimeout
    from ros2_support import (
        Netns,
        cdr_setbool_request,
        cdr_setbool_response,
        context,
        read_setbool_response,
        require_netns,
    )

    require_netns()
    ns = Netns()
    a = b = None
    records = []
    handler = logging.Handler()
    handler.emit = records.append
    logging.getLogger("minros.ros2").addHandler(handler)
    try:
        a, b = context(ns), context(ns)
        calls = threading.Semaphore(0)

        def decline(request):
            calls.release()
            return None if request[4] else cdr_setbool_response(True, "answered")
        b.create_node("server").create_service("/set", "std_srvs/srv/SetBool", decline)
        client = a.create_node("client").create_client("/set", "std_srvs/srv/SetBool")
        assert client.wait_for_service(10)
        with pytest.raises(ServiceTimeout):
            client.call(cdr_setbool_request(True), 0.5)
        assert calls.acquire(timeout=1)
        assert read_setbool_response(client.call(cdr_setbool_request(False), 5)) == \
            (True, "answered")
        assert not [r for r in records if "handler failed" in r.getMessage()]
    finally:
        logging.getLogger("minros.ros2").removeHandler(handler)
        for ctx in (a, b):
            if ctx is not None:
                ctx.shutdown()
        ns.delete()


# -- the command ---------------------------------------------------------------------------------

def _command(*args: str, env_extra=None):
    import os
    import subprocess
    import sys

    env = {k: v for k, v in os.environ.items() if not k.startswith("ROS_")}
    env.update(env_extra or {})
    return subprocess.run([sys.executable, "-m", "minros", "ros2", *args], capture_output=True,
                          text=True, timeout=60, env=env)


def test_command_help_and_mistakes_are_one_line_before_anything_joins_dds(tmp_path):
    """--help; a bad configuration and a missing master each end the command with one line
    and a status, before any DDS participant exists (nothing is sent)."""
    from support import free_port

    out = _command("--help")
    assert out.returncode == 0 and "--bridge-all-1to2-topics" in out.stdout
    bad = tmp_path / "bridge.yaml"
    bad.write_text("topics:\n  - {topic: /a, type: std_msgs/msg/String, queue_size: -3}\n")
    out = _command("--config", str(bad))
    assert out.returncode == 2
    assert out.stderr.strip().splitlines() == [
        f"minros ros2: error: {bad}: topics[0] (/a): queue_size must be a whole number (0 or "
        f"absent: 100), got -3"]
    out = _command("--domain", "300")
    assert (out.returncode, out.stderr.strip()) == (
        2, "minros ros2: error: --domain 300: a number from 0 to 232")
    port = free_port()
    out = _command(env_extra={"ROS_MASTER_URI": f"http://127.0.0.1:{port}"})
    assert out.returncode == 1
    assert out.stderr.strip() == (
        f"minros ros2: error: cannot reach the ROS master at http://127.0.0.1:{port}: start one "
        "with `minros core` (or roscore), or set ROS_MASTER_URI")
    assert "Traceback" not in out.stderr


def test_print_pairs_lists_ros1_bridges_pairs():
    out = _command("--print-pairs")
    assert out.returncode == 0
    assert "  - 'sensor_msgs/msg/CameraInfo' (ROS 2) <=> 'sensor_msgs/CameraInfo' (ROS 1)" in \
        out.stdout
    assert "  - 'std_srvs/srv/SetBool' (ROS 2) <=> 'std_srvs/SetBool' (ROS 1)" in out.stdout
    assert "'tf2_msgs/msg/TFMessage' (ROS 2) <=> 'tf/tfMessage' (ROS 1)" in out.stdout
