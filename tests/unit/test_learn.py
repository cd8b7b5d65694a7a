"""``minros learn``'s checkers, pure: every exercise with a right answer, wrong answers (each
with the hint that names the mistake), and a trace that lacks what the exercise asks for.
The traces are built here the way minros.wire.trace writes them."""

from __future__ import annotations

import hashlib
import re
import struct
from typing import Dict, List

import pytest

from minros import learn
from minros.cli import learn as learn_cli
from minros.learn import catalog
from minros.learn.evidence import connections, latency
from minros.learn.model import tokens
from zenoh_support import require_zenoh

MASTER = "http://localhost:11311/"
ME = "http://localhost:40001/"
TALKER = "http://localhost:40002/"


def call(method: str, args: list, reply, *, served: bool = False, node: str = "/me",
         pid: int = 1, uri: str = MASTER, t: float = 1.0) -> dict:
    return {"ev": "xmlrpc.serve" if served else "xmlrpc.call", "t": t, "pid": pid, "node": node,
            "uri": uri, "method": method, "args": args, "reply": reply}


def conn(cid: int, side: str, out: Dict[str, str], inn: Dict[str, str], *, pid: int = 1,
         local: str = "127.0.0.1:50000", remote: str = "127.0.0.1:38000",
         frames_in: List[dict] = (), frames_out: List[dict] = (), t: float = 2.0) -> List[dict]:
    base = {"pid": pid, "node": "/me", "conn": cid}
    events = [dict(base, ev="tcp.open", t=t, side=side, local=local, remote=remote)]
    first, second = (out, inn) if side == "connect" else (inn, out)
    for fields, direction in ((first, "out" if side == "connect" else "in"),
                              (second, "in" if side == "connect" else "out")):
        if fields:
            events.append(dict(base, ev="tcpros.header", t=t, dir=direction,
                               fields=[[k, v] for k, v in fields.items()]))
    for i, frame in enumerate(frames_in):
        events.append(dict(base, ev="tcpros.frame", dir="in", n=i + 1, t=t + 0.01 * (i + 1),
                           **frame))
    for i, frame in enumerate(frames_out):
        events.append(dict(base, ev="tcpros.frame", dir="out", n=i + 1, t=t + 0.01 * (i + 1),
                           **frame))
    return events


def attempt(number: int, answer: str, mine: List[dict], facts=None, **traces):
    facts = dict({"me": "/tmp/me.jsonl", "dir": "/tmp", "master": MASTER, "port": 11311},
                 **(facts or {}))
    return learn.check(number, answer, dict(traces, me=mine), facts)


def test_the_list_has_at_least_ten_short_exercises_numbered_from_one():
    exercises = learn.exercises()
    assert len(exercises) >= 10
    assert [ex.number for ex in exercises] == list(range(1, len(exercises) + 1))
    assert all(ex.minutes <= 5 for ex in exercises)
    assert len({ex.slug for ex in exercises}) == len(exercises)
    covered = " | ".join(ex.covers for ex in exercises)
    for topic in ("registerSubscriber", "both connection headers", "md5sum by hand",
                  "byte by byte", "md5 mismatch", "restarting the master", "latched",
                  "tcp_nodelay", "probe and a persistent call", "two masters"):
        assert topic in covered
    with pytest.raises(LookupError, match="minros learn --list"):
        learn.exercise(99)


def test_every_task_fills_its_fields_and_names_the_check_command():
    facts = {"dir": "/d", "me": "/d/me.jsonl", "master": MASTER, "master_b": TALKER,
             "port": 1, "port_b": 2, "python": "python3", "master_pid": 7, "reading": "x",
             "frame_id": "attic", "temperature": 1.0, "variance": 0.5, "zenoh_port": 3,
             "door_latch": "1", "window_latch": "0", "field": "value"}
    for ex in learn.exercises():
        for variant in ex.variants:
            text = ex.task_text(dict(facts, variant=variant))
            assert not re.search(r"<[a-z_]+>", text), (ex.number, variant, text)  # all filled
            assert f"minros learn check {ex.number} {ex.form(variant)}" in text
    eleven = learn.exercise(11)
    assert eleven.form("relay") == "CALLERID N" and eleven.form("zenoh") == "CALLERID KEY"
    zenoh = eleven.task_text(dict(facts, variant="zenoh"))
    assert "listens on tcp/127.0.0.1:3," in zenoh and "key expression" in zenoh
    assert "how many TCPROS" in eleven.task_text(dict(facts, variant="relay"))


def test_answers_are_read_as_words_whatever_the_learner_copied():
    assert tokens('["http://localhost:1/"], "x"') == ["http://localhost:1/", "x"]
    assert tokens("registerPublisher, registerSubscriber") == ["registerPublisher",
                                                              "registerSubscriber"]


# --------------------------------------------------------------------------- 1


def _subscribed() -> List[dict]:
    return [call("registerSubscriber", ["/me", "/chatter", "*", ME],
                 [1, "Subscribed to [/chatter]", [TALKER]]),
            call("requestTopic", ["/me", "/chatter", [["TCPROS"]]],
                 [1, "ready on localhost:38000", ["TCPROS", "localhost", 38000]], uri=TALKER)]


def test_1_the_masters_answer():
    assert attempt(1, TALKER, _subscribed()).ok
    assert attempt(1, f'["{TALKER.rstrip("/")}"]', _subscribed()).ok
    wrong = attempt(1, "localhost:38000", _subscribed())
    assert not wrong.ok and "TCPROS port" in wrong.text and "never knows data ports" in wrong.hint
    assert "your own node" in attempt(1, ME, _subscribed()).text
    assert "the master itself" in attempt(1, MASTER, _subscribed()).text
    assert "Give your answer" in attempt(1, "", _subscribed()).text
    assert "has no registerSubscriber" in attempt(1, TALKER, []).text


# --------------------------------------------------------------------------- 2


def _headers() -> List[dict]:
    sub = {"callerid": "/me", "md5sum": "*", "message_definition": "", "tcp_nodelay": "0",
           "topic": "/chatter", "type": "*"}
    pub = {"callerid": "/talker", "latching": "0", "md5sum": catalog.STRING_MD5,
           "message_definition": "string data", "topic": "/chatter", "type": "std_msgs/String"}
    return conn(1, "connect", sub, pub)


def test_2_both_headers():
    right = attempt(2, "tcp_nodelay latching", _headers())
    assert right.ok and "tcp_nodelay=0" in right.text and "latching=0" in right.text
    assert attempt(2, "tcp_nodelay=0 latching=0", _headers()).ok
    swapped = attempt(2, "latching tcp_nodelay", _headers())
    assert not swapped.ok and "other way round" in swapped.text
    assert not attempt(2, "md5sum type", _headers()).ok
    assert "no connection to /chatter" in attempt(2, "a b", []).text


# --------------------------------------------------------------------------- 3


def _published() -> Dict[str, List[dict]]:
    mine = [call("registerPublisher", ["/me", "/news", "std_msgs/String", ME],
                 [1, "Registered", ["http://localhost:40003/"]])]
    master = [call("publisherUpdate", ["/master", "/news", [ME]], [1, "", 0], node="/master",
                   uri="http://localhost:40003/")]
    return {"mine": mine, "master": master}


def test_3_publisher_update():
    t = _published()
    right = attempt(3, f"publisherUpdate {ME}", t["mine"], master=t["master"])
    assert right.ok and "the master's trace shows it" in right.text
    wrong = attempt(3, f"registerPublisher {ME}", t["mine"], master=t["master"])
    assert not wrong.ok and "your node's call to the master" in wrong.text
    assert "listener calling your node" in attempt(3, f"requestTopic {ME}", t["mine"]).text
    facts = {"listener_uri": "http://localhost:40003/"}
    listener = attempt(3, "publisherUpdate http://localhost:40003/", t["mine"], facts)
    assert not listener.ok and "listener's own URI" in listener.text
    assert "has no registerPublisher" in attempt(3, "publisherUpdate x", []).text


# --------------------------------------------------------------------------- 4


def _temperature_frame(frame_id: str = "attic", value: float = 21.25, var: float = 0.5) -> bytes:
    text = frame_id.encode()
    return struct.pack("<IIII", 3, 1700000000, 5, len(text)) + text + struct.pack("<dd", value,
                                                                                  var)


def _received(body: bytes) -> List[dict]:
    sub = {"callerid": "/me", "topic": "/temperature", "type": "*", "md5sum": "*"}
    pub = {"callerid": "/thermometer", "topic": "/temperature",
           "type": "sensor_msgs/Temperature"}
    return conn(1, "connect", sub, pub, frames_in=[{"len": len(body), "head": body.hex()}])


def test_4_a_frame_byte_by_byte():
    mine = _received(_temperature_frame())
    right = attempt(4, "attic 21.25", mine)
    assert right.ok and any('header.frame_id = "attic"' in line for line in right.details)
    assert any(line.strip().startswith("0000000000403540") and "21.25" in line
               for line in right.details)
    assert attempt(4, "21.25 attic", mine).ok
    big = struct.unpack(">d", struct.pack("<d", 21.25))[0]
    assert "little-endian" in attempt(4, f"attic {big!r}", mine).hint
    assert "temperature comes first" in attempt(4, "attic 0.5", mine).hint
    assert "decode its bytes" in attempt(4, f"{b'attic'.hex()} 21.25", mine).text
    assert "4-byte little-endian length" in attempt(4, "atti 21.25", mine).hint
    cut = _received(_temperature_frame())
    cut[-1]["head"] = cut[-1]["head"][:40]  # the trace kept only 20 bytes
    assert "has no whole frame" in attempt(4, "attic 21.25", cut).text


# --------------------------------------------------------------------------- 5


def test_5_an_md5sum_by_hand():
    from minros.msgs import get_message_class

    header = get_message_class("std_msgs/Header")._md5sum
    text = f"uint8 CELSIUS=0\nuint8 FAHRENHEIT=1\n{header} header\nfloat64 level\nuint8 unit"
    facts = {"field": "level"}
    right = hashlib.md5(text.encode()).hexdigest()
    # the same sum genmsg's rules give, from the message system's own parser
    from minros.msgs.spec import compute_md5_text, md5_hex, parse_msg

    spec = parse_msg(catalog.READING_MSG.format(field="level"), "learn_msgs/Reading")
    assert md5_hex(compute_md5_text(spec, lambda _t: header)) == right
    assert attempt(5, right, [], facts).ok
    assert attempt(5, right.upper(), [], facts).ok
    newline = hashlib.md5((text + "\n").encode()).hexdigest()
    assert "no newline at the end" in attempt(5, newline, [], facts).hint
    named = hashlib.md5(text.replace(header, "Header").encode()).hexdigest()
    assert "its own md5sum" in attempt(5, named, [], facts).hint
    order = hashlib.md5(f"{header} header\nfloat64 level\nuint8 unit\nuint8 CELSIUS=0\n"
                        "uint8 FAHRENHEIT=1".encode()).hexdigest()
    assert "Constants come first" in attempt(5, order, [], facts).hint
    assert "not an md5sum" in attempt(5, "12ab", [], facts).text
    other = attempt(5, "0" * 32, [], facts)
    assert not other.ok and other.hint


# --------------------------------------------------------------------------- 6


def _refused() -> List[dict]:
    stale = {"callerid": "/old_listener", "md5sum": "da5909fbe378aeaf85e547e830cc1bb7",
             "message_definition": "int32 data", "tcp_nodelay": "0", "topic": "/greetings",
             "type": "std_msgs/String"}
    return conn(1, "accept", {"error": "Client [/old_listener] wants topic [/greetings] to "
                              "have datatype/md5sum [...]"}, stale)


def test_6_an_md5_mismatch():
    right = attempt(6, "da5909fbe378aeaf85e547e830cc1bb7 publisher", _refused())
    assert right.ok and "error=Client [/old_listener]" in right.text
    mine = attempt(6, f"{catalog.STRING_MD5} publisher", _refused())
    assert not mine.ok and "your publisher's md5sum" in mine.text
    side = attempt(6, "da5909fbe378aeaf85e547e830cc1bb7 subscriber", _refused())
    assert not side.ok and "error=" in side.hint
    assert "no refused connection" in attempt(6, "x publisher", []).text


# --------------------------------------------------------------------------- 7


def _latching(latched: str = "/door") -> List[dict]:
    events = []
    for cid, topic in enumerate(("/door", "/window"), 1):
        flag = "1" if topic == latched else "0"
        frames = [{"len": 14, "head": "0a000000" + "00" * 10}] if flag == "1" else []
        events += conn(cid, "connect", {"topic": topic, "callerid": "/me"},
                       {"topic": topic, "latching": flag, "callerid": topic + "_sensor"},
                       frames_in=frames, local=f"127.0.0.1:5000{cid}")
    return events


def test_7_latched_or_not():
    right = attempt(7, "/window latching=1", _latching("/window"))
    assert right.ok and "/door's said latching=0 and sent 0" in right.text
    assert attempt(7, "window latching=1", _latching("/window")).ok
    wrong = attempt(7, "/door latching=1", _latching("/window"))
    assert not wrong.ok and "latching= field" in wrong.hint
    assert "key=value" in attempt(7, "/window", _latching("/window")).text
    only_door = [ev for ev in _latching() if ev.get("conn") == 1]
    assert "/window" in attempt(7, "/door latching=1", only_door).text


# --------------------------------------------------------------------------- 8


def _service_calls() -> List[dict]:
    probe = conn(1, "connect", {"callerid": "/me", "md5sum": "*", "probe": "1",
                                "service": "/add_two_ints"},
                 {"callerid": "/server", "service": "/add_two_ints", "type": "x/Y"})
    calls = conn(2, "connect", {"callerid": "/me", "md5sum": "6a2e", "persistent": "1",
                                "service": "/add_two_ints"},
                 {"callerid": "/server", "service": "/add_two_ints", "type": "x/Y"},
                 frames_out=[{"len": 16, "head": ""}] * 3,
                 frames_in=[{"len": 8, "head": "", "ok": 1}] * 3)
    return probe + calls


def test_8_the_probe_and_the_persistent_connection():
    right = attempt(8, "2 probe=1", _service_calls())
    assert right.ok and "carried 3 requests" in right.text and "ok byte 1" in right.text
    assert "persistent=True keeps one connection" in attempt(8, "4 probe=1",
                                                             _service_calls()).hint
    assert "Count the probe too" in attempt(8, "1 probe=1", _service_calls()).hint
    assert "persistent=1 is on the connection that carried" in attempt(
        8, "2 persistent=1", _service_calls()).text
    assert "no connection to /add_two_ints" in attempt(8, "2 probe=1", []).text


# --------------------------------------------------------------------------- 9


def _nagle() -> Dict[str, List[dict]]:
    mine, sensor = [], []
    for cid, flag in ((1, "0"), (2, "1")):
        local, remote = f"127.0.0.1:5100{cid}", "127.0.0.1:38000"
        frames = [{"len": 1004, "off": 200 + 1008 * i, "head": ""} for i in range(20)]
        mine += conn(cid, "connect", {"topic": "/sensor", "tcp_nodelay": flag},
                     {"topic": "/sensor", "callerid": "/sensor"}, local=local, remote=remote,
                     frames_in=frames, t=10.0 * cid)
        sensor += conn(cid, "accept", {"topic": "/sensor", "callerid": "/sensor"},
                       {"topic": "/sensor", "tcp_nodelay": flag}, local=remote, remote=local,
                       frames_out=frames, t=10.0 * cid - (0.04 if flag == "0" else 0.001),
                       pid=2)
    return {"mine": mine, "sensor": sensor}


def test_9_nagle_and_tcp_nodelay():
    t = _nagle()
    right = attempt(9, "tcp_nodelay=1", t["mine"], sensor=t["sensor"])
    assert right.ok
    assert any("tcp_nodelay=0: 20 frames: median 40.00 ms" in line for line in right.details)
    assert any("tcp_nodelay=1: 20 frames: median 1.00 ms" in line for line in right.details)
    assert "0 is the default" in attempt(9, "tcp_nodelay=0", t["mine"]).text
    assert "key=value" in attempt(9, "TCP_NODELAY", t["mine"]).hint
    plain_only = [ev for ev in t["mine"] if ev.get("conn") == 1]
    assert "one with --tcpnodelay" in attempt(9, "tcp_nodelay=1", plain_only).text


def test_latency_pairs_the_frames_of_both_ends_by_stream_offset():
    t = _nagle()
    receiver = connections(t["mine"], topic="/sensor")[0]
    lat = latency(receiver, t["sensor"])
    assert lat is not None and lat.frames == 20 and round(lat.max, 3) == 40.0
    assert latency(receiver, []) is None


# --------------------------------------------------------------------------- 10


def _restart() -> Dict[str, List[dict]]:
    old = [{"ev": "process", "t": 1.0, "pid": 10, "node": "minros"}]
    new = [{"ev": "process", "t": 5.0, "pid": 11, "node": "minros"},
           call("registerPublisher", ["/talker", "/chatter", "std_msgs/String", TALKER],
                [1, "", []], served=True, node="/master", pid=11, t=6.0),
           call("registerSubscriber", ["/listener", "/chatter", "std_msgs/String", ME],
                [1, "", [TALKER]], served=True, node="/master", pid=11, t=6.5)]
    return {"master": old, "master2": new}


def test_10_the_master_restarts():
    t = _restart()
    right = attempt(10, "registerPublisher registerSubscriber", [], **t)
    assert right.ok and any("/talker called registerPublisher 1.0 s after" in line
                            for line in right.details)
    assert "node to node" in attempt(10, "requestTopic", [], **t).text
    assert not attempt(10, "registerPublisher", [], **t).ok
    assert "No trace of a new master" in attempt(10, "x", [], master=t["master"]).text
    same = attempt(10, "x", [], master=t["master"], master2=t["master"])
    assert "written by the first master" in same.text
    waiting = attempt(10, "x", [], master=t["master"], master2=t["master2"][:1])
    assert "no registration of /chatter yet" in waiting.text


# --------------------------------------------------------------------------- 11


def _across(sender: str = "/relay") -> List[dict]:
    b = "http://localhost:11312/"
    return [{"ev": "node", "t": 0.5, "pid": 1, "node": "/me", "name": "/me", "uri": ME},
            call("registerSubscriber", ["/me", "/chatter", "*", ME],
                 [1, "Subscribed", ["http://localhost:40009/"]], uri=b)] + conn(
        1, "connect", {"topic": "/chatter", "callerid": "/me"},
        {"topic": "/chatter", "callerid": sender, "type": "std_msgs/String",
         "md5sum": catalog.STRING_MD5})


def test_11_a_topic_across_two_masters_through_a_relay():
    facts = {"master_b": "http://localhost:11312/", "hops": 2, "variant": "relay"}
    right = attempt(11, "/relay 2", _across(), facts, master=[])
    assert right.ok and "Master A's trace has no call from your node (/me)" in right.text
    assert "--via zenoh does the same" in right.text
    assert "master A" in attempt(11, "/talker 2", _across(), facts).text
    assert "pipe, not TCPROS" in attempt(11, "/relay 3", _across(), facts).hint
    on_a = attempt(11, "/relay 2", _across(),
                   {"master_b": "http://localhost:9/", "variant": "relay"})
    assert not on_a.ok and "ROS_MASTER_URI=http://localhost:9/" in on_a.hint


KEY = "7374645f6d7367732f537472696e67/992ce8a1687cec8c8bd883ec73ca41d1/*/chatter"
ZENOH = {"master_b": "http://localhost:11312/", "variant": "zenoh", "answer_form": "CALLERID KEY"}


def _master_b_heard_the_bridge() -> List[dict]:
    return [call("registerPublisher", ["/minros_zenoh", "/chatter", "std_msgs/String",
                                       "http://localhost:40011/"],
                 [1, "Registered [/minros_zenoh] as publisher of [/chatter]", []],
                 served=True, node="/master", uri="")]


def test_11_through_zenoh_the_sender_and_the_key():
    mine = _across("/minros_zenoh")
    right = attempt(11, f"/minros_zenoh {KEY}", mine, ZENOH, master=[],
                    master_b=_master_b_heard_the_bridge())
    assert right.ok, right
    assert "Master B's trace shows /minros_zenoh's registerPublisher for /chatter" in right.text
    assert f"under {KEY}" in right.text and "no call from your node (/me)" in right.text
    # quoted, with commas, as a learner may paste it
    assert attempt(11, f'"/minros_zenoh", "{KEY}"', mine, ZENOH).ok
    # without master B's trace the text still says what happened, not what a trace shows
    assert "registered /chatter as a publisher on master B" in attempt(
        11, f"/minros_zenoh {KEY}", mine, ZENOH).text


@pytest.mark.parametrize("answer, text, hint", [
    (f"/talker {KEY}", "/talker publishes on master A", "reached master B through the bridges"),
    (f"/rosout {KEY}", "not who sent you the message", "callerid field of the second header"),
    ("/minros_zenoh", "now the key", "minros zenoh keys /chatter"),
    ("/minros_zenoh std_msgs/String", "is not the key", "one part of the key"),
    (f"/minros_zenoh ros1_discovery_info/*/pub/{KEY}", "is not the key", "beacon"),
    ("/minros_zenoh 537472696e67/992ce8a1687cec8c8bd883ec73ca41d1/*/chatter", "is not the key",
     "hex of the type's whole name, std_msgs/String"),
    (f"/minros_zenoh {KEY.replace('992c', '0000')}", "is not the key", "md5sum of the publisher"),
    (f"/minros_zenoh {KEY.replace('/*/', '/robot/')}", "is not the key", "namespace is '*'"),
    (f"/minros_zenoh {KEY}/", "is not the key", "no '/' at either end"),
    (f"/minros_zenoh {KEY.replace('/*/', '/')}", "is not the key", "four parts"),
    (f"/minros_zenoh {KEY.replace('chatter', 'Chatter')}", "is not the key", "topic's name"),
])
def test_11_through_zenoh_wrong_answers_get_a_hint_that_names_the_mistake(answer, text, hint):
    result = attempt(11, answer, _across("/minros_zenoh"), ZENOH)
    assert not result.ok and text in result.text and hint in result.hint, result


def test_11_through_zenoh_needs_the_learners_subscription_on_master_b():
    assert "has no registerSubscriber" in attempt(11, "x", [], ZENOH).text
    on_a = attempt(11, f"/minros_zenoh {KEY}", _across("/minros_zenoh"),
                   dict(ZENOH, master_b="http://localhost:9/"))
    assert not on_a.ok and "ROS_MASTER_URI=http://localhost:9/" in on_a.hint
    asked = attempt(11, "", _across("/minros_zenoh"), ZENOH)
    assert not asked.ok and asked.hint == "minros learn check 11 CALLERID KEY"


def test_the_checkers_key_is_minros_zenohs():
    from minros.zenoh.keys import data_key

    for topic, type_name, md5 in (("/chatter", "std_msgs/String", catalog.STRING_MD5),
                                  ("/robot/scan", "sensor_msgs/LaserScan", "9" * 32)):
        assert catalog.zenoh_key(topic, type_name, md5) == data_key(topic, type_name, md5)


def _without_zenoh(monkeypatch) -> None:
    import sys

    monkeypatch.setitem(sys.modules, "zenoh", None)  # find_spec raises: as if not installed


def test_exercise_11_goes_through_zenoh_when_it_is_installed(tmp_path):
    from minros.learn.session import Runner

    require_zenoh()
    ex = learn.exercise(11)
    assert list(ex.variants) == ["zenoh", "relay"] and not ex.planned
    assert ex.default_variant == "zenoh" and ex.unavailable() == {}
    assert Runner(ex, tmp_path).variant == "zenoh"
    assert Runner(ex, tmp_path, variant="relay").variant == "relay"
    bridges = [p for p in ex.processes("zenoh") if p.argv[:2] == ("minros", "zenoh")]
    assert [p.master for p in bridges] == ["a", "b"]
    for bridge in bridges:  # nothing reaches the LAN: loopback endpoints, no scouting
        assert "--no-multicast-scouting" in bridge.argv
        listen = [bridge.argv[i + 1] for i, arg in enumerate(bridge.argv) if arg == "--listen"]
        assert listen and all(e.startswith("tcp/127.0.0.1:") for e in listen), bridge.argv


def test_without_eclipse_zenoh_the_relay_is_the_default_and_zenoh_says_why(
        tmp_path, monkeypatch, capsys):
    from minros.learn.session import LearnError, Runner
    from minros.web.learning import exercise_json

    _without_zenoh(monkeypatch)
    ex = learn.exercise(11)
    assert ex.default_variant == "relay" and Runner(ex, tmp_path).variant == "relay"
    assert "pip install minros[zenoh]" in ex.unavailable()["zenoh"]
    with pytest.raises(LearnError) as err:
        Runner(ex, tmp_path, variant="zenoh")
    assert str(err.value) == ("--via zenoh: the Zenoh bridge needs the eclipse-zenoh package, "
                              "which minros installs as an extra: pip install minros[zenoh]; "
                              "--via relay runs without it")
    with pytest.raises(LearnError, match="no variant 'carrier-pigeon'"):
        Runner(ex, tmp_path, variant="carrier-pigeon")
    assert learn_cli.main(["11", "--via", "zenoh", "--dir", str(tmp_path)]) == 1
    err_text = capsys.readouterr().err
    assert err_text.count("\n") == 1 and "pip install minros[zenoh]" in err_text
    assert not list(tmp_path.iterdir())  # refused before anything started
    listed = exercise_json(ex, tmp_path)
    assert listed["variant"] == "relay" and listed["answer_form"] == "CALLERID N"
    assert listed["planned"]["zenoh"].startswith("zenoh: the Zenoh bridge needs")

    # a start without --via says in one line why it is not through Zenoh
    class Started(Runner):
        def start(self):
            raise LearnError(f"(the test stops here: {self.variant})")

    monkeypatch.setattr("minros.learn.session.Runner", Started)
    assert learn_cli.main(["11", "--dir", str(tmp_path)]) == 1
    out, err = capsys.readouterr()
    assert out.splitlines()[1] == (
        "(not --via zenoh here: the Zenoh bridge needs the eclipse-zenoh package, which minros "
        "installs as an extra: pip install minros[zenoh])")
    assert "(the test stops here: relay)" in err


def test_a_start_gives_each_port_field_a_free_port(tmp_path):
    from minros.learn.model import Exercise, Process
    from minros.learn.session import Runner, _port_fields

    ex = learn.exercise(11)
    assert _port_fields(ex.processes("zenoh")) == ["zenoh_port"]
    assert _port_fields(ex.processes("relay")) == []
    one = Exercise(98, "ports", "Ports", 1, "ports", task="{zenoh_port}", answer_form="",
                   check=lambda a: None, variants={"": (Process("x", ("m", "{zenoh_port}")),)})
    runner = Runner(one, tmp_path)
    facts = runner._facts()
    assert isinstance(facts["zenoh_port"], int) and 0 < facts["zenoh_port"] < 65536


# --------------------------------------------------------------------------- the command


def test_the_command_lists_and_refuses_in_one_line(tmp_path, capsys):
    assert learn_cli.main(["--list"]) == 0
    out = capsys.readouterr().out
    assert out.splitlines()[1].split()[:2] == ["1", "The"] and " 11  " in out
    assert learn_cli.main(["check", "3", "--dir", str(tmp_path), "x"]) == 1
    err = capsys.readouterr().err.strip()
    assert err.count("\n") == 0 and "start it with minros learn 3" in err
    assert learn_cli.main(["42"]) == 1
    assert "there is no exercise 42" in capsys.readouterr().err
    assert learn_cli.main(["check", "one"]) == 1
    assert "not an exercise number" in capsys.readouterr().err


@pytest.mark.slow  # over half a CPU-second of its own
def test_an_exercise_whose_traces_grow_too_big_stops(tmp_path):
    import threading

    from minros.learn import session
    from minros.learn.session import Runner

    said: List[str] = []
    runner = Runner(learn.exercise(1), tmp_path, say=said.append)
    runner.folder.mkdir(parents=True)
    (runner.folder / "master.jsonl").write_bytes(b"x" * 3000)
    (runner.folder / "master.log").write_bytes(b"x" * 9000)  # logs do not count
    assert runner.too_big(limit=4000) == ""
    (runner.folder / "me.jsonl").write_bytes(b"x" * 2000)
    assert runner.too_big(limit=4000).startswith(f"its traces in {runner.folder} passed")
    (runner.folder / "talker.jsonl").write_bytes(b"x" * (session.TRACE_LIMIT - 4000))
    session_every = session.SIZE_EVERY
    try:
        session.SIZE_EVERY = 0.0
        runner.wait(threading.Event(), poll=0.01, limit=5.0)
    finally:
        session.SIZE_EVERY = session_every
    assert len(said) == 1 and said[0].startswith("minros learn: stopping: its traces in")


def test_an_exercise_left_running_stops_by_itself(tmp_path):
    import threading

    from minros.learn.session import Runner

    said: List[str] = []
    runner = Runner(learn.exercise(1), tmp_path, say=said.append)
    runner.wait(threading.Event(), poll=0.01, limit=0.05)
    assert len(said) == 1 and "stopping after" in said[0]
