"""rosbridge and Foxglove sessions fed what a hostile client sends, without sockets: each bad
input gets one error to that client, and nothing the client chooses makes the server build
more than the data it sent (a fake WebState and a real Outbox)."""

from __future__ import annotations

import json
import struct
import tracemalloc

import pytest

from minros.msgs import Time, get_message_class
from minros.web import foxglove_protocol as fp
from minros.web.outbox import Outbox
from minros.web.rosapi import Graph
from minros.web.state import Options


class FakeState:
    """What the sessions use of WebState, without ROS."""

    def __init__(self) -> None:
        self.graph = Graph(topic_types={"/chatter": "std_msgs/String"})
        self.options = Options()
        self.use_sim_time = False
        self.started = 1.0
        self.publishers = {}
        self.published = []
        self.tapped = []

    def topic_allowed(self, topic):
        return True

    def service_allowed(self, name):
        return True

    def topic_type(self, topic):
        return self.graph.topic_types.get(topic)

    def message_class(self, type_name):
        return get_message_class(type_name)

    def acquire_publisher(self, client, topic, data_class, latch=False, queue_size=100):
        state = self

        class Pub:
            def __init__(self):
                self.data_class = data_class
                self.clients = {client}

            def publish(self, msg):
                state.published.append((topic, msg))

        pub = self.publishers[topic] = Pub()
        return pub

    def release_publisher(self, client, topic, delay=None):
        self.publishers.pop(topic, None)

    def tap(self, topic, type_name, key, listener):
        self.tapped.append((topic, key))

    def untap(self, topic, key):
        self.tapped.remove((topic, key))

    def add_graph_listener(self, key, listener):
        pass

    def remove_graph_listener(self, key):
        pass

    def service_type(self, name):
        raise LookupError(name)

    def poke(self):
        pass

    def now(self):
        return Time(1, 0)


def frames(outbox: Outbox) -> list:
    out = []
    while True:
        got = outbox.get(timeout=0)
        if got is None:
            return out
        slot, item = got
        rendered = item if slot is None else slot.render(item)
        out += [rendered] if isinstance(rendered, (str, bytes)) else list(rendered)


def rosbridge():
    from minros.web.rosbridge import RosbridgeSession

    outbox, state = Outbox(), FakeState()
    return RosbridgeSession("test", state, outbox, lambda reason: None,
                            run_async=lambda fn: fn()), outbox, state


def foxglove():
    from minros.web.foxglove import FoxgloveSession

    outbox, state = Outbox(), FakeState()
    return FoxgloveSession("test", state, outbox, lambda reason: None,
                           run_async=lambda fn: fn()), outbox, state


def deep_json(depth: int) -> str:
    return '{"op": "publish", "msg": ' + "[" * depth + "]" * depth + "}"


# -- nesting a parser cannot follow ------------------------------------------------------------

@pytest.mark.parametrize("data", [
    deep_json(100_000),
    "[" * 100_000,  # cut short as well
    b"\x81" * 100_000 + b"\xf6",  # CBOR: 100,000 nested arrays (not UTF-8)
    b"\xc6\x81" * 50_000 + b"\xf6",  # CBOR: tags and arrays that happen to be UTF-8
])
def test_deep_json_or_cbor_gets_one_rosbridge_status(data, caplog):
    session, outbox, _ = rosbridge()
    session.receive(data)  # was: RecursionError out of receive(), the server's traceback
    replies = [json.loads(f) for f in frames(outbox)]
    assert len(replies) == 1 and replies[0]["op"] == "status" and replies[0]["level"] == "error"
    assert "nested too deeply" in replies[0]["msg"] or "not" in replies[0]["msg"]
    # the session goes on
    session.receive(json.dumps({"op": "subscribe", "topic": "/chatter", "id": "s"}))
    assert frames(outbox) == [] and session.subscriptions


def test_deep_json_gets_one_foxglove_status():
    session, outbox, _ = foxglove()
    session.receive(deep_json(100_000))
    replies = [json.loads(f) for f in frames(outbox)]
    assert replies == [{"op": "status", "level": fp.ERROR,
                        "message": "Invalid JSON message: nested too deeply to read"}]


# -- sizes the client picks ------------------------------------------------------------------

def test_foxglove_client_schema_with_a_huge_fixed_array_builds_nothing():
    """clientAdvertise of `float64[100000000] a` and a 13-byte message took 43 -> 807 MB:
    a default instance was built before the message was found short."""
    session, outbox, state = foxglove()
    session.receive(json.dumps({"op": "advertise", "channels": [{
        "id": 1, "topic": "/big", "encoding": "ros1", "schemaName": "evil_msgs/Big",
        "schema": "float64[100000000] a"}]}))
    assert frames(outbox) == []
    tracemalloc.start()
    try:
        session.receive(struct.pack("<BI", fp.CLIENT_MESSAGE_DATA, 1) + b"\0" * 13)
        peak = tracemalloc.get_traced_memory()[1]
    finally:
        tracemalloc.stop()
    assert peak < 1 << 20
    (reply,) = [json.loads(f) for f in frames(outbox)]
    assert reply["op"] == "status" and reply["level"] == fp.ERROR
    assert "is not a valid evil_msgs/Big" in reply["message"] and "truncated" in reply["message"]
    assert state.published == []
    # a whole message of a sane schema goes through
    session.receive(json.dumps({"op": "advertise", "channels": [{
        "id": 2, "topic": "/ok", "encoding": "ros1", "schemaName": "evil_msgs/Small",
        "schema": "float64[2] a"}]}))
    session.receive(struct.pack("<BI2d", fp.CLIENT_MESSAGE_DATA, 2, 1.5, 2.5))
    assert frames(outbox) == [] and len(state.published) == 1


def test_fragment_size_one_makes_fragments_as_they_are_sent():
    """fragment_size 1 built every fragment of a message at once (a 1080p image: ~1.3 GB per
    client); now the writer takes them one at a time."""
    from minros.web.rosbridge import fragment

    text = json.dumps({"op": "publish", "topic": "/x", "msg": {"data": "y" * 1_000_000}})
    tracemalloc.start()
    try:
        parts = fragment(text, 1, 7)
        first = [json.loads(next(parts)) for _ in range(3)]
        peak = tracemalloc.get_traced_memory()[1]
    finally:
        tracemalloc.stop()
    assert peak < 64 << 10
    assert first[0] == {"op": "fragment", "id": 7, "data": "{", "num": 0, "total": len(text)}
    assert "".join(json.loads(f)["data"] for f in fragment(text, 4096, 8)) == text


def test_fragments_a_client_sends_are_bounded_by_their_count_too(monkeypatch):
    """32 MB of 1-character fragments held ~3 GB (a dict entry each), and 64 messages in
    progress were allowed 32 MB each."""
    from minros.web import rosbridge as rb

    monkeypatch.setattr(rb, "MAX_QUEUE_BYTES", 1 << 20)
    session, outbox, _ = rosbridge()
    sent = 0
    while not (replies := frames(outbox)):
        session.receive(json.dumps({"op": "fragment", "id": "f", "data": "x", "num": sent,
                                    "total": 1 << 30}))
        sent += 1
    assert sent <= (1 << 20) // rb.FRAGMENT_OVERHEAD
    assert "does not fit" in json.loads(replies[0])["msg"] and session.fragments == {}
    # two messages in progress share the bound
    half = "y" * (600 << 10)
    session.receive(json.dumps({"op": "fragment", "id": 1, "data": half, "num": 0, "total": 2}))
    session.receive(json.dumps({"op": "fragment", "id": 2, "data": half, "num": 0, "total": 2}))
    assert "does not fit" in json.loads(frames(outbox)[0])["msg"]
    assert list(session.fragments) == [1]


def test_snapshot_sizes_are_capped_and_a_feed_keeps_few_of_them():
    """/snapshot?width=16384&height=16384 of a small camera took ~900 MB; and every size a
    viewer asked for stayed cached on a frame that stayed the latest."""
    import cv2
    import numpy as np

    from cv_bridge import CvBridge
    from minros.web import video
    from minros.web.state import Incoming

    assert video.output_size(640, 480, video.StreamParams("/c", width=16384, height=16384)) \
        == (2880, 2880)
    assert video.output_size(640, 480, video.StreamParams("/c", width=320, height=240)) == (320, 240)
    assert video.output_size(640, 480, video.StreamParams("/c", width=1280)) == (1280, 480)
    big = video.output_size(8000, 6000, video.StreamParams("/c", width=16384, height=12288))
    assert big[0] * big[1] <= 8000 * 6000 and abs(big[0] / big[1] - 4 / 3) < 0.01

    class Tap:
        class state:
            class decoder:
                @staticmethod
                def class_for_header(header):
                    return get_message_class("sensor_msgs/Image")

    msg = CvBridge().cv2_to_imgmsg(np.full((48, 64, 3), 90, np.uint8), "bgr8")
    incoming = Incoming(Tap, msg.serialize_to_bytes(), {"type": "sensor_msgs/Image"}, 1)
    feed = video.ImageFeed("/cam")
    feed.push(incoming)
    _, jpeg, _ = feed.jpeg(video.StreamParams("/cam", width=16384, height=16384))
    assert cv2.imdecode(np.frombuffer(jpeg, np.uint8), cv2.IMREAD_COLOR).shape == (2880, 2880, 3)
    for width in range(1, 200):
        feed.jpeg(video.StreamParams("/cam", width=width, height=10))
    assert len(feed._jpegs) <= video.MAX_PARAM_SETS and len(feed._locks) <= video.MAX_PARAM_SETS
    assert [k for k in incoming._cache if k != "decoded"] == []


@pytest.mark.parametrize("entry, text", [
    ({"name": "/g", "type": "float64", "value": "abc"}, "a float64 value must be a number"),
    ({"name": "/g", "type": "float64", "value": 10 ** 400}, "a float64 value must be a number"),
    ({"name": "/g", "type": "float64_array", "value": 5}, "must be a list of numbers"),
    ({"name": "/g", "type": "byte_array", "value": "!!!"}, "must be base64 text"),
])
def test_foxglove_parameter_values_of_the_wrong_type_get_a_status(entry, text):
    """These raised ValueError/TypeError out of the session: a traceback in the server log."""
    session, outbox, state = foxglove()
    state.set_param = lambda name, value: pytest.fail("nothing may be set")
    session.receive(json.dumps({"op": "setParameters", "parameters": [entry]}))
    (reply,) = [json.loads(f) for f in frames(outbox)]
    assert reply["op"] == "status" and text in reply["message"]


def test_rosbridge_publisher_queue_is_kept_bounded():
    session, outbox, state = rosbridge()
    sizes = []
    state.acquire_publisher = lambda client, topic, cls, latch=False, queue_size=100: sizes.append(
        queue_size) or FakeState.acquire_publisher(state, client, topic, cls, latch, queue_size)
    for size in (0, 10 ** 30, 5):  # 0 is an unbounded queue in rospy
        session.receive(json.dumps({"op": "advertise", "topic": f"/t{size % 7}",
                                    "type": "std_msgs/String", "queue_size": size}))
    assert sizes == [1, 1000, 5]
    session.receive(json.dumps({"op": "advertise", "topic": "/u", "type": "std_msgs/String",
                                "queue_size": "x"}))
    assert "queue_size" in json.loads(frames(outbox)[-1])["msg"]


def test_what_one_client_may_hold_is_bounded(monkeypatch):
    """Subscriptions, advertisements and their ids each cost memory and a master
    registration: a client asking for a million was served."""
    from minros.web import foxglove as fx
    from minros.web import rosbridge as rb

    monkeypatch.setattr(rb, "MAX_PER_CLIENT", 5)
    monkeypatch.setattr(rb, "MAX_IDS_PER_TOPIC", 3)
    session, outbox, state = rosbridge()
    for i in range(6):
        session.receive(json.dumps({"op": "subscribe", "topic": f"/s{i}", "type": "std_msgs/String"}))
    assert len(session.subscriptions) == 5
    assert "the most one client may have" in json.loads(frames(outbox)[-1])["msg"]
    for i in range(5):
        session.receive(json.dumps({"op": "subscribe", "topic": "/s0", "id": i,
                                    "type": "std_msgs/String"}))
    assert len(session.subscriptions["/s0"].ids) == 3
    for i in range(6):
        session.receive(json.dumps({"op": "advertise", "topic": f"/a{i}", "type": "std_msgs/String"}))
    assert len(session.advertised) == 5
    assert "advertised topics" in json.loads(frames(outbox)[-1])["msg"]

    monkeypatch.setattr(fx, "MAX_PER_CLIENT", 2)
    fox, out, _ = foxglove()
    fox.channels = {1: ("/chatter", "std_msgs/String")}
    fox.receive(json.dumps({"op": "subscribe", "subscriptions": [
        {"id": i, "channelId": 1} for i in range(4)]}))
    assert len(fox.subscriptions) == 2
    fox.receive(json.dumps({"op": "advertise", "channels": [
        {"id": i, "topic": f"/c{i}", "encoding": "ros1", "schemaName": "std_msgs/String"}
        for i in range(3)]}))
    assert len(fox.client_channels) == 2
    assert sum("the most one client may" in f for f in frames(out)) == 3
