"""minros's RTPS against Eclipse Cyclone DDS 11.0.1 (cyclonedds-python), a second,
independent DDS: pub/sub both ways, fragmented samples, transient local, and services in
rmw_cyclonedds's in-band form (tests/cyclone_agent.py), in one network namespace."""

from __future__ import annotations

import hashlib
import threading

import pytest

from ros2_support import (
    CYCLONE_AGENT,
    CYCLONE_URI,
    HASHES,
    Agent,
    Netns,
    cdr_setbool_request,
    cdr_setbool_response,
    cdr_string,
    cdr_uint8_array,
    context,
    cyclone_python,
    read_setbool_response,
    read_string,
    read_uint8_array,
    require_cyclone,
)

pytestmark = [pytest.mark.interop, pytest.mark.timeout(120)]

STRING = "std_msgs/msg/String"
ARRAY = "std_msgs/msg/UInt8MultiArray"


@pytest.fixture(scope="module")
def world(tmp_path_factory):
    require_cyclone()
    tmp = tmp_path_factory.mktemp("cyclone")
    ns = Netns()
    agent = ctx = None
    try:
        agent = Agent(ns, cyclone_python(), CYCLONE_AGENT, "cyclone_agent", tmp,
                      env={"CYCLONEDDS_URI": CYCLONE_URI})
        ctx = context(ns)
        node = ctx.create_node("minros_node")
        yield {"agent": agent, "ctx": ctx, "node": node}
    finally:
        if ctx is not None:
            ctx.shutdown()
        if agent is not None:
            agent.close()
        ns.delete()


def test_cyclone_talker_to_minros_and_back_in_order(world):
    agent, node = world["agent"], world["node"]
    got = []
    done = threading.Event()

    def on_message(payload, info):
        got.append(read_string(bytes(payload)))
        if len(got) == 200:
            done.set()
    sub = node.create_subscription("cy_in", STRING, on_message, type_hash=HASHES[STRING])
    agent("pub", id="talker", topic="cy_in", type=STRING, qos={"depth": 200})
    assert agent("matched", id="talker")["count"] == 1
    assert sub.wait_for_publishers(1, 10)
    agent("publish", id="talker", count=200)
    assert done.wait(20), f"{len(got)} of 200"
    assert got == [f"hello {i}" for i in range(200)]
    assert [i.vendor for i in node.get_publishers_info_by_topic("cy_in")] == ["Cyclone DDS"]
    # minros -> Cyclone
    from minros.ros2.rmw import QoSProfile

    pub = node.create_publisher("cy_out", STRING, QoSProfile(depth=200),
                                type_hash=HASHES[STRING])
    agent("sub", id="listener", topic="cy_out", type=STRING, qos={"depth": 200})
    assert pub.wait_for_subscriptions(1, 10)
    for i in range(200):
        pub.publish(cdr_string(f"hello {i}"))
    answer = agent("received", id="listener", count=200, timeout=20)
    assert answer["items"] == [f"hello {i}" for i in range(200)]
    sub.destroy()
    pub.destroy()


def test_fragmented_samples_both_ways(world):
    """300 KB arrays: DATA_FRAG in both directions (Cyclone fragments at 1344 bytes, several
    per datagram; minros at 64000, one per datagram)."""
    agent, node = world["agent"], world["node"]
    got = []
    done = threading.Event()

    def on_array(payload, info):
        got.append(hashlib.md5(read_uint8_array(payload)).hexdigest())
        if len(got) == 3:
            done.set()
    sub = node.create_subscription("cy_array_in", ARRAY, on_array,
                                   type_hash=HASHES[ARRAY])
    agent("pub", id="arrays", topic="cy_array_in", type=ARRAY)
    assert agent("matched", id="arrays")["count"] == 1
    assert sub.wait_for_publishers(1, 10)
    sent = agent("publish", id="arrays", count=3, size=300_000, timeout=60)["md5"]
    assert done.wait(30), f"{len(got)} of 3"
    assert got == sent
    pub = node.create_publisher("cy_array_out", ARRAY, type_hash=HASHES[ARRAY])
    agent("sub", id="arrays_in", topic="cy_array_out", type=ARRAY)
    assert pub.wait_for_subscriptions(1, 10)
    want = []
    for i in range(3):
        data = bytes([(i * 5 + 2) % 256]) * 300_000
        want.append(hashlib.md5(data).hexdigest())
        pub.publish(cdr_uint8_array(data))
    answer = agent("received", id="arrays_in", count=3, timeout=30)
    assert [x["md5"] for x in answer["items"]] == want
    sub.destroy()
    pub.destroy()


def test_transient_local_to_a_late_cyclone_reader(world):
    from minros.ros2.rmw import LATCHED

    agent, node = world["agent"], world["node"]
    pub = node.create_publisher("cy_latched", STRING, LATCHED, type_hash=HASHES[STRING])
    pub.publish(cdr_string("before"))
    pub.publish(cdr_string("latched"))
    agent("sub", id="late", topic="cy_latched", type=STRING,
          qos={"durability": "transient_local", "depth": 1})
    assert agent("received", id="late", count=1, timeout=10)["items"] == ["latched"]
    pub.destroy()


def test_services_in_cyclones_in_band_form_both_ways(world):
    agent, node = world["agent"], world["node"]
    seen = []

    def setbool(request):
        seen.append(bytes(request))
        return cdr_setbool_response(bool(request[4]), f"minros set {bool(request[4])}")
    srv = node.create_service("minros_cy_set", "std_srvs/srv/SetBool", setbool)
    answer = agent("call", name="minros_cy_set", data=True, count=3)
    assert answer["ready"]
    assert answer["results"] == [{"success": True, "message": "minros set True"}] * 3
    # the handler saw plain requests: the header was taken off
    assert [r[:5] for r in seen] == [cdr_setbool_request(True)] * 3  # (then CDR padding)
    agent("serve", id="cy_server", name="cyclone_set")
    client = node.create_client("cyclone_set", "std_srvs/srv/SetBool")
    assert client.wait_for_service(10)
    import time

    time.sleep(0.2)  # the server's reply writer matches this client's reader on its own time
    for value in (True, False):
        assert read_setbool_response(client.call(cdr_setbool_request(value), 5)) == \
            (value, f"cyclone set {value}")
    srv.destroy()
    client.destroy()
