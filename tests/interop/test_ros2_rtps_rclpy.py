"""minros's RTPS and rmw layer against real rclpy (Jazzy on Fast DDS 2.14, Kilted on Fast DDS
3.2), each distro's checks in one network namespace with one rclpy process (tests/ros2_agent.py).
"""

from __future__ import annotations

import hashlib
import logging
import os
import signal
import threading
import time

import pytest

from ros2_support import (
    AGENT,
    CDR_TRIGGER_REQUEST,
    HASHES,
    Agent,
    Netns,
    cdr_image,
    cdr_setbool_request,
    cdr_setbool_response,
    cdr_string,
    context,
    read_image,
    read_setbool_response,
    read_string,
    require_ros2,
    ros2_python,
    wait_for,
)

pytestmark = [pytest.mark.interop, pytest.mark.timeout(180)]

STRING = "std_msgs/msg/String"
IMAGE = "sensor_msgs/msg/Image"


@pytest.fixture(scope="module", params=["jazzy", "kilted"])
def world(request, tmp_path_factory):
    """(distro, namespace, rclpy agent, minros context, its node)."""
    distro = request.param
    require_ros2(distro)
    tmp = tmp_path_factory.mktemp(f"ros2-{distro}")
    ns = Netns()
    agent = ctx = None
    try:
        agent = Agent(ns, ros2_python(distro), AGENT, "rclpy_agent", tmp)
        started = time.monotonic()
        ctx = context(ns)
        node = ctx.create_node("minros_node")
        yield {"distro": distro, "ns": ns, "agent": agent, "ctx": ctx, "node": node,
               "started": started, "tmp": tmp}
    finally:
        if ctx is not None:
            ctx.shutdown()
        if agent is not None:
            agent.close()
        ns.delete()


def test_rclpy_lists_the_node_within_a_second_with_its_endpoints_and_type_hash(world):
    agent, node, ctx = world["agent"], world["node"], world["ctx"]
    pub = node.create_publisher("minros_chatter", STRING, type_hash=HASHES[STRING])
    seen = agent("graph", want_node="minros_node", timeout=5, topic="/minros_chatter")
    elapsed = time.monotonic() - world["started"]
    assert ("minros_node", "/") in [tuple(n) for n in seen["nodes"]]
    assert elapsed < 1.0, f"rclpy saw the node after {elapsed:.2f} s"
    # its endpoint and type, as SEDP and ros_discovery_info tell rclpy
    deadline = time.monotonic() + 5
    while not seen.get("publishers") and time.monotonic() < deadline:
        seen = agent("graph", topic="/minros_chatter")
    assert ["/minros_chatter", [STRING]] in seen["topics"]
    assert seen["publishers"] == [{"node": "minros_node", "namespace": "/", "type": STRING,
                                   "hash": HASHES[STRING], "reliability": "RELIABLE",
                                   "durability": "VOLATILE"}]
    # and minros sees rclpy's node the same way
    assert ctx.graph.wait_until(
        lambda g: ("rclpy_agent", "/") in g.node_names_and_namespaces(), 5)
    pub.destroy()
    gone = wait_for(lambda: not agent("graph", topic="/minros_chatter")["publishers"], 5,
                    "the publisher to leave rclpy's graph")
    assert gone


def test_rclpy_talker_to_minros_1000_of_1000_in_order(world):
    agent, node = world["agent"], world["node"]
    got = []
    done = threading.Event()

    def on_message(payload, info):
        got.append(read_string(bytes(payload)))
        if len(got) == 1000:
            done.set()
    sub = node.create_subscription("talk_in", STRING, on_message, type_hash=HASHES[STRING])
    agent("pub", id="talker", topic="talk_in", type=STRING,
          qos={"depth": 1000})
    assert agent("matched", id="talker")["count"] == 1
    agent("publish", id="talker", count=1000)
    assert done.wait(20), f"{len(got)} of 1000 arrived"
    assert got == [f"hello {i}" for i in range(1000)]
    info = node.get_publishers_info_by_topic("talk_in")
    assert [(i.node_name, i.type_hash, i.vendor) for i in info] == \
        [("rclpy_agent", HASHES[STRING], "Fast DDS")]
    sub.destroy()


def test_minros_talker_to_rclpy_listener_1000_of_1000_in_order(world):
    agent, node = world["agent"], world["node"]
    from minros.ros2.rmw import QoSProfile

    pub = node.create_publisher("talk_out", STRING, QoSProfile(depth=1000),
                                type_hash=HASHES[STRING])
    agent("sub", id="listener", topic="talk_out", type=STRING, qos={"depth": 1000})
    assert pub.wait_for_subscriptions(1, 10)
    for i in range(1000):
        pub.publish(cdr_string(f"hello {i}"))
    got = agent("received", id="listener", count=1000, timeout=20)
    assert got["count"] == 1000
    assert got["items"] == [f"hello {i}" for i in range(1000)]
    assert pub.wait_for_acknowledgments(5)
    pub.destroy()


def test_transient_local_reaches_late_joiners_both_ways(world):
    from minros.ros2.rmw import LATCHED

    agent, node = world["agent"], world["node"]
    pub = node.create_publisher("latched_out", STRING, LATCHED, type_hash=HASHES[STRING])
    pub.publish(cdr_string("old"))
    pub.publish(cdr_string("latched"))
    # rclpy joins later: it gets the last sample (depth 1), not the earlier one
    agent("sub", id="late", topic="latched_out", type=STRING,
          qos={"durability": "transient_local", "depth": 1})
    got = agent("received", id="late", count=1, timeout=10)
    assert got["items"] == ["latched"]
    # an rclpy latched publisher, then minros subscribes
    agent("pub", id="tl", topic="latched_in", type=STRING,
          qos={"durability": "transient_local", "depth": 1})
    agent("publish", id="tl", count=3, prefix="state")
    arrived = []
    sub = node.create_subscription("latched_in", STRING,
                                   lambda p, i: arrived.append(read_string(bytes(p))), LATCHED,
                                   type_hash=HASHES[STRING])
    wait_for(lambda: arrived, 10, "the latched sample")
    time.sleep(0.2)  # anything more would be a bug: only the last sample is history
    assert arrived == ["state 2"]
    sub.destroy()
    pub.destroy()


def test_best_effort_rclpy_subscriber(world):
    agent, node = world["agent"], world["node"]
    pub = node.create_publisher("be_out", STRING, type_hash=HASHES[STRING])
    # depth 100: a busy machine may leave rclpy's executor behind; its history keeps them
    agent("sub", id="be", topic="be_out", type=STRING,
          qos={"reliability": "best_effort", "depth": 100})
    assert pub.wait_for_subscriptions(1, 10)
    time.sleep(0.1)  # the subscriber's side matches on its own SEDP; best effort does not wait
    for i in range(50):
        pub.publish(cdr_string(f"be {i}"))
        time.sleep(0.002)
    got = agent("received", id="be", count=50, timeout=5)["items"]
    numbers = [int(x.split()[1]) for x in got]
    assert numbers == sorted(numbers) and len(numbers) >= 45, numbers
    pub.destroy()


def test_1080p_rgb8_images_both_ways(world):
    agent, node = world["agent"], world["node"]
    w, h = 1920, 1080
    # rclpy -> minros
    frames = []
    done = threading.Event()

    def on_image(payload, info):
        img = read_image(payload)
        frames.append((img["width"], img["height"], img["encoding"],
                       hashlib.md5(img["data"]).hexdigest()))
        if len(frames) == 5:
            done.set()
    sub = node.create_subscription("image_in", IMAGE, on_image, type_hash=HASHES[IMAGE])
    agent("pub", id="cam", topic="image_in", type=IMAGE)
    assert agent("matched", id="cam")["count"] == 1
    sent = agent("publish", id="cam", image=True, count=5)["md5"]
    assert done.wait(30), f"{len(frames)} of 5 frames"
    assert frames == [(w, h, "rgb8", md5) for md5 in sent]
    sub.destroy()
    # minros -> rclpy
    pub = node.create_publisher("image_out", IMAGE, type_hash=HASHES[IMAGE])
    agent("sub", id="view", topic="image_out", type=IMAGE)
    assert pub.wait_for_subscriptions(1, 10)
    want = []
    for i in range(5):
        data = bytes([(i * 11 + 5) % 256]) * (w * h * 3)
        want.append(hashlib.md5(data).hexdigest())
        pub.publish(cdr_image(w, h, data))
    got = agent("received", id="view", count=5, timeout=30)["items"]
    assert [(x["width"], x["height"], x["size"], x["md5"]) for x in got] == \
        [(w, h, w * h * 3, md5) for md5 in want]
    assert pub.wait_for_acknowledgments(10)
    pub.destroy()


def test_services_rclpy_client_to_minros_server(world):
    agent, node = world["agent"], world["node"]
    calls = []

    def setbool(request):
        calls.append(request)
        on = bool(request[4])
        return cdr_setbool_response(on, "minros set " + ("on" if on else "off"))
    srv = node.create_service("minros_set", "std_srvs/srv/SetBool", setbool,
                              request_hash=HASHES["std_srvs/srv/SetBool_Request"],
                              response_hash=HASHES["std_srvs/srv/SetBool_Response"])
    trig = node.create_service("minros_trigger", "std_srvs/srv/Trigger",
                               lambda req: cdr_setbool_response(True, "minros triggered"))
    answer = agent("call", id="c1", name="minros_set", type="std_srvs/srv/SetBool", data=True,
                   count=3)
    assert answer["ready"], "rclpy's wait_for_service did not see the minros service"
    assert answer["results"] == [{"success": True, "message": "minros set on"}] * 3
    answer = agent("call", id="c1", name="minros_set", type="std_srvs/srv/SetBool", data=False)
    assert answer["results"] == [{"success": False, "message": "minros set off"}]
    answer = agent("call", id="c2", name="minros_trigger", type="std_srvs/srv/Trigger")
    assert answer["results"] == [{"success": True, "message": "minros triggered"}]
    assert len(calls) == 4
    services = dict((k, v) for k, v in agent("graph")["services"])
    assert services.get("/minros_set") == ["std_srvs/srv/SetBool"]
    srv.destroy()
    trig.destroy()


def test_services_minros_client_to_rclpy_server(world):
    agent, node = world["agent"], world["node"]
    agent("serve", id="s1", name="rclpy_set", type="std_srvs/srv/SetBool")
    agent("serve", id="s2", name="rclpy_trigger", type="std_srvs/srv/Trigger")
    client = node.create_client("rclpy_set", "std_srvs/srv/SetBool",
                                request_hash=HASHES["std_srvs/srv/SetBool_Request"],
                                response_hash=HASHES["std_srvs/srv/SetBool_Response"])
    assert client.wait_for_service(10)
    for value in (True, False, True):
        reply = client.call(cdr_setbool_request(value), timeout=5)
        assert read_setbool_response(reply) == (value, f"rclpy set {value}")
    trigger = node.create_client("rclpy_trigger", "std_srvs/srv/Trigger")
    assert trigger.wait_for_service(10)
    assert read_setbool_response(trigger.call(CDR_TRIGGER_REQUEST, timeout=5)) == \
        (True, "rclpy triggered")
    # concurrent calls each get their own reply
    futures = [client.call_async(cdr_setbool_request(i % 2 == 0)) for i in range(10)]
    assert [read_setbool_response(f.result(5))[0] for f in futures] == \
        [i % 2 == 0 for i in range(10)]
    client.destroy()
    trigger.destroy()


def test_incompatible_qos_is_one_log_line_naming_both(world, caplog):
    from minros.ros2.rmw import SENSOR_DATA

    agent, node = world["agent"], world["node"]
    caplog.set_level(logging.WARNING, logger="minros.ros2")
    pub = node.create_publisher("mismatch", STRING, SENSOR_DATA, type_hash=HASHES[STRING])
    agent("sub", id="strict", topic="mismatch", type=STRING, qos={"reliability": "reliable"})
    wait_for(lambda: [r for r in caplog.records if "mismatch" in r.getMessage()], 10,
             "the QoS log line")
    time.sleep(0.5)
    lines = [r.getMessage() for r in caplog.records if "mismatch" in r.getMessage()]
    assert len(lines) == 1, lines
    assert "reliability: the writer offers BEST_EFFORT, the reader requests RELIABLE" in lines[0]
    assert "writer here [BEST_EFFORT, VOLATILE, KEEP_LAST 5]" in lines[0]
    assert "[RELIABLE, VOLATILE" in lines[0] and "Fast DDS" in lines[0]
    assert pub.get_subscription_count() == 0
    pub.destroy()


def test_a_sample_that_does_not_decode_is_dropped_with_one_line(world, caplog):
    """Garbage from a (minros) writer on a topic rclpy and minros both read: minros drops it
    with one line per publisher and goes on; rclpy too."""
    agent, node, ns = world["agent"], world["node"], world["ns"]
    caplog.set_level(logging.WARNING, logger="minros.ros2")
    good = []

    def check(payload):
        read_string(bytes(payload))
    sub = node.create_subscription("garbage", STRING, lambda p, i: good.append(
        read_string(bytes(p))), check=check, type_hash=HASHES[STRING])
    agent("sub", id="g", topic="garbage", type=STRING)
    other = context(ns)
    try:
        bad = other.create_node("garbage_writer").create_publisher(
            "garbage", STRING, type_hash=HASHES[STRING])
        assert bad.wait_for_subscriptions(2, 10)
        bad.publish(b"\x00\x07\x00\x00garbage")            # not plain CDR
        bad.publish(b"\x00\x01\x00\x00\xff\xff\xff\x7fxx")  # a string longer than the sample
        bad.publish(cdr_string("fine"))
        wait_for(lambda: good, 5, "the good sample")
        assert good == ["fine"]
        lines = [r.getMessage() for r in caplog.records if "does not decode" in r.getMessage()]
        assert len(lines) == 1 and "garbage" in lines[0], lines
        assert sub.rejected == 2
        assert "fine" in agent("received", id="g", count=1, timeout=5)["items"]
    finally:
        other.shutdown()
    sub.destroy()


@pytest.mark.timeout(120)
def test_a_peer_killed_is_dropped_after_its_lease_and_minros_goes_on(world, caplog):
    """SIGKILL of an rclpy process: no goodbye; minros drops it after its lease (Fast DDS's
    default in ROS 2: 20 s) with one line and keeps serving the others."""
    if world["distro"] != "jazzy":
        pytest.skip("one distro is enough for the lease (20 s of waiting)")
    caplog.set_level(logging.INFO, logger="minros.ros2")
    ctx, ns = world["ctx"], world["ns"]
    victim = Agent(ns, ros2_python(world["distro"]), AGENT, "victim", world["tmp"])
    assert ctx.graph.wait_until(lambda g: ("victim", "/") in g.node_names_and_namespaces(), 10)
    killed = time.monotonic()
    os.kill(victim.pid, signal.SIGKILL)
    victim.proc.wait(10)
    assert ctx.graph.wait_until(
        lambda g: ("victim", "/") not in g.node_names_and_namespaces(), 40)
    gone_after = time.monotonic() - killed
    assert 15 < gone_after < 25, gone_after
    lines = [r.getMessage() for r in caplog.records if "is gone" in r.getMessage()]
    assert len(lines) == 1 and "lease of 20 s" in lines[0] and "Fast DDS" in lines[0], lines
    # the survivor is still served
    assert ("rclpy_agent", "/") in ctx.graph.node_names_and_namespaces()
    pub = world["node"].create_publisher("after_kill", STRING, type_hash=HASHES[STRING])
    world["agent"]("sub", id="after", topic="after_kill", type=STRING)
    assert pub.wait_for_subscriptions(1, 10)
    pub.publish(cdr_string("still here"))
    assert world["agent"]("received", id="after", count=1)["items"] == ["still here"]
    pub.destroy()


@pytest.mark.parametrize("distro", ["jazzy", "kilted"])
def test_localhost_only_discovery_without_multicast(distro, tmp_path, caplog):
    """No multicast at all (lo as a host has it: no MULTICAST flag, no route):
    ROS_AUTOMATIC_DISCOVERY_RANGE=LOCALHOST makes Fast DDS announce itself to the unicast
    ports of participant ids 0-31 on 127.0.0.1, as minros does: they find each other."""
    require_ros2(distro)
    caplog.set_level(logging.INFO, logger="minros.ros2")
    ns = Netns(multicast=False)
    agent = ctx = None
    try:
        agent = Agent(ns, ros2_python(distro), AGENT, "local_agent", tmp_path,
                      env={"ROS_AUTOMATIC_DISCOVERY_RANGE": "LOCALHOST"})
        ctx = context(ns)
        assert ctx.participant.mc_sock is None
        node = ctx.create_node("minros_local")
        pub = node.create_publisher("local", STRING, type_hash=HASHES[STRING])
        agent("sub", id="l", topic="local", type=STRING)
        seen = agent("graph", want_node="minros_local", timeout=10)
        assert ("minros_local", "/") in [tuple(n) for n in seen["nodes"]]
        assert pub.wait_for_subscriptions(1, 10)
        pub.publish(cdr_string("by unicast"))
        assert agent("received", id="l", count=1)["items"] == ["by unicast"]
        assert not [r for r in caplog.records if r.levelno >= logging.WARNING]
    finally:
        if ctx is not None:
            ctx.shutdown()
        if agent is not None:
            agent.close()
        ns.delete()
