"""The page's Wire view, server side, without sockets or a browser: trace items as the page's
steps (the text ``minros trace show`` prints, the details as data), the bounded store, the
feed that follows files (missing, cut, overwritten, not a trace, a directory that fills up),
and the page session's ``wire`` frames."""

from __future__ import annotations

import json

from hypothesis import given, settings
from hypothesis import strategies as st
from test_trace import STRING_MD5, _ev, _talker_first_trace, _write
from test_web_page import replies, session

from minros.tools.trace import merge, show
from minros.tools.trace.merge import Call, Connection, Follower, Wire
from minros.web import wiretrace
from minros.web.wiretrace import WireFeed, WireModel, step_json


class Clock:
    def __init__(self) -> None:
        self.now = 0.0

    def __call__(self) -> float:
        return self.now


def _feed(*specs, max_steps: int = wiretrace.MAX_STEPS) -> WireFeed:
    return WireFeed([str(spec) for spec in specs], max_steps=max_steps, clock=Clock())


def _steps(feed: WireFeed) -> list:
    steps, _removed, _status, _seq = feed.changes(0, [])
    return sorted(steps, key=lambda s: (s.get("conn_t") or s["t"], s["id"]))


def _status(feed: WireFeed) -> dict:
    return feed.changes(0, [])[2]


# -- items as steps ---------------------------------------------------------------------------

def test_a_run_becomes_the_numbered_steps_show_prints(tmp_path):
    feed = _feed(_write(tmp_path / "t.jsonl", _talker_first_trace()))
    feed.poll()
    steps = _steps(feed)
    assert {(s["kind"], s["name"]) for s in steps} == {("topic", "/chatter")}
    # the course's numbers: [0], [1] answered by [2], [3] answered by [4], [5] x3, [6]
    numbers = []
    for step in steps:
        numbers += [step["step"]] + ([step["reply"]["step"]] if step["what"] == "call" else [])
    assert [n for n in numbers if n] == ["0", "1", "2", "3", "4", "5", "5", "5", "6"]
    # each step says what minros trace show says, word for word
    lines = "\n".join(show.render(merge.split_runs([merge.load(str(tmp_path / "t.jsonl"))]),
                                  show.Filter()))
    for step in steps:
        assert step["text"] in lines and step["who"] in lines
        for line in step.get("lines", []):
            assert line in lines
    register, subscribe, request, opened, sub_header, pub_header, message, closed = steps
    assert register["text"] == ('registerPublisher("/talker", "/chatter", "std_msgs/String", '
                                '"http://localhost:40001/")')
    assert register["type"] == "std_msgs/String" and register["nodes"] == ["/master", "/talker"]
    # XML-RPC arguments by the names the Master API gives them, the answer split
    assert register["details"]["args"] == [
        ["caller_id", "/talker"], ["topic", "/chatter"], ["topic_type", "std_msgs/String"],
        ["caller_api", "http://localhost:40001/"]]
    assert subscribe["reply"] == {"step": "2", "t": 1000.51, "text": '<- 1, "Subscribed to '
                                  '[/chatter]", ["http://localhost:40001/"]'}
    assert (subscribe["details"]["code"], subscribe["details"]["status"],
            subscribe["details"]["value"]) == (1, "Subscribed to [/chatter]",
                                               ["http://localhost:40001/"])
    assert [a[0] for a in request["details"]["args"]] == ["caller_id", "topic", "protocols"]
    assert request["details"]["value"] == ["TCPROS", "localhost", 40010]
    # the connection: opened, both headers as key=value, the first message decoded
    assert opened["what"] == "open" and opened["who"] == "/listener -> /talker"
    assert opened["step"] == "5" and opened["conn"] == sub_header["conn"] == message["conn"]
    assert sub_header["conn_t"] == opened["t"]  # a connection's steps stay together
    assert dict(sub_header["details"]["fields"])["md5sum"] == STRING_MD5
    assert sub_header["details"]["fields"][4] == ["message_definition", "string data\n"]
    assert "message_definition=string data" in sub_header["lines"]
    assert pub_header["who"] == "/talker -> /listener" and ["latching", "0"] in pub_header[
        "details"]["fields"]
    assert message["text"].startswith("message 1: length prefix 11000000 = 17 bytes")
    assert message["details"]["msg"] == {"data": "hello world 0"}
    assert message["details"]["prefix"] == "11000000" and message["details"]["len"] == 17
    assert closed["what"] == "close" and closed["details"]["stats"]["frames_in"] == 1
    json.dumps(steps)  # plain JSON, as sent


def test_arg_names_come_from_the_api_handlers():
    assert wiretrace.arg_names("publisherUpdate") == ("caller_id", "topic", "publishers")
    assert wiretrace.arg_names("subscribeParam") == ("caller_id", "caller_api", "key")
    assert wiretrace.arg_names("noSuchMethod") == ()
    call = Call(t=1.0, t_reply=1.001, method="noSuchMethod", args=["/a", 2])
    assert step_json(call)["details"]["args"] == [["argument 1", "/a"], ["argument 2", 2]]


def test_long_header_values_are_cut_in_the_details():
    conn = Connection(client="127.0.0.1:1", server="127.0.0.1:2", kind="topic", name="/big")
    text = "x" * (wiretrace.VALUE_LIMIT + 10)
    item = Wire(t=1.0, what="header", conn=conn, dir="c2s", len=20,
                fields=[["topic", "/big"], ["message_definition", text]])
    value = step_json(item)["details"]["fields"][1][1]
    assert value.startswith("x" * 100) and value.endswith("…(+10 chars)")


# -- the store --------------------------------------------------------------------------------

def _call(t: float, topic: str, method: str = "registerPublisher", caller: str = "/a") -> Call:
    return Call(t=t, t_reply=t, method=method, args=[caller, topic, "std_msgs/String", "http://a/"],
                reply=[1, "ok", []], caller=caller, callee="/master")


def test_the_store_keeps_the_newest_steps_without_pushing_a_quiet_section_out():
    model = WireModel(max_steps=10)
    model.add(_call(0.0, "/quiet"))
    model.add(_call(0.1, "/quiet", "registerSubscriber", "/b"))
    for i in range(20):
        model.add(_call(1.0 + i, "/busy"))
    assert len(model.steps) == 10 and model.dropped == 12
    quiet = [s for s in model.steps.values() if s["name"] == "/quiet"]
    busy = [s for s in model.steps.values() if s["name"] == "/busy"]
    assert len(quiet) == 2 and len(busy) == 8  # the largest section gave way
    assert [s["t"] for s in busy] == [13.0 + i for i in range(8)]  # its newest


def test_since_gives_what_changed_and_repeated_calls_are_counted():
    model = WireModel()
    model.add(_call(0.0, "/x"))
    seq = model.seq
    probe = Call(t=1.0, t_reply=1.0, method="getPid", args=["/master"], reply=[1, "", 42],
                 caller="/master", callee="/talker")
    model.add(probe)
    for i in range(4):
        model.add(Call(t=2.0 + i, t_reply=2.0 + i, method="getPid", args=["/master"],
                       reply=[1, "", 42], caller="/master", callee="/talker"))
    other = [s for s in model.steps.values() if s["kind"] == "other"]
    assert len(other) == 1 and other[0]["count"] == 5 and other[0]["last"] == 5.0
    assert other[0]["plumbing"] is True  # the master's probes: hidden by default on the page
    changed = model.since(seq)
    assert [s["id"] for s in changed] == [other[0]["id"]]  # once, at its newest
    assert model.since(model.seq) == []
    # a failure is not the same call again
    model.add(Call(t=9.0, t_reply=9.0, method="getPid", args=["/master"], error="refused",
                   caller="/master", callee="/talker"))
    assert len([s for s in model.steps.values() if s["kind"] == "other"]) == 2


def test_a_connection_is_placed_by_its_header_and_completed_by_the_other_end(tmp_path):
    events = _talker_first_trace()
    listener = [e for e in events if e["pid"] == 2]
    talker = [e for e in events if e["pid"] == 1]
    feed = _feed(_write(tmp_path / "listener.jsonl", listener))
    feed.poll()
    by_text = {s["text"].split(":")[0]: s for s in _steps(feed)}
    message = by_text["message 1"]
    assert "msg" not in message["details"]  # the listener did not decode it
    assert "latency_ms" not in message["details"]
    seq = feed.model.seq
    _write(tmp_path / "talker.jsonl", talker)
    feed.specs.append(str(tmp_path / "talker.jsonl"))
    feed.poll()
    changed = {s["id"]: s for s in feed.changes(seq, [])[0]}
    assert changed[message["id"]]["details"]["msg"] == {"data": "hello world 0"}
    assert changed[message["id"]]["details"]["latency_ms"] == 10.0
    # one step per exchange, whichever ends were traced
    assert sum(s["what"] == "header" for s in _steps(feed)) == 2
    # a connection that never names a topic or service is not listed
    stray = [_ev(1001.0, 3, "/x", "process", argv=["x"], master="http://localhost:11311/"),
             _ev(1001.1, 3, "/x", "tcp.open", conn=1, side="connect", local="127.0.0.1:1",
                 remote="127.0.0.1:2"),
             _ev(1001.2, 3, "/x", "tcp.close", conn=1, local="127.0.0.1:1",
                 remote="127.0.0.1:2")]
    count = len(feed.model.steps)
    _write(tmp_path / "stray.jsonl", stray)
    feed.specs.append(str(tmp_path / "stray.jsonl"))
    feed.poll()
    assert len(feed.model.steps) == count


# -- following files --------------------------------------------------------------------------

def _lines(events) -> bytes:
    return "".join(json.dumps(e) + "\n" for e in events).encode()


def test_a_missing_file_is_waited_for_and_a_directory_is_watched(tmp_path):
    missing = tmp_path / "later.jsonl"
    folder = tmp_path / "run"
    folder.mkdir()
    feed = _feed(missing, folder, tmp_path / "g*.jsonl")
    feed.poll()
    problems = _status(feed)["problems"]
    assert problems == [f"{folder} holds no *.jsonl trace yet: waiting for one",
                        f"no file matches {tmp_path / 'g*.jsonl'} yet: waiting for one",
                        f"{missing} does not exist (yet): waiting for it"]
    told = []
    feed.listen("page", lambda: told.append(1))
    events = _talker_first_trace()
    (folder / "talker.jsonl").write_bytes(_lines(e for e in events if e["pid"] == 1))
    (folder / "notes.txt").write_text("not a trace, not followed\n")
    (tmp_path / "g1.jsonl").write_bytes(_lines(e for e in events if e["pid"] == 2))
    missing.write_bytes(b"")
    feed.poll()
    status = _status(feed)
    assert status["problems"] == [] and told
    assert sorted(status["files"]) == sorted(
        [str(missing), str(folder / "talker.jsonl"), str(tmp_path / "g1.jsonl")])
    assert len(_steps(feed)) == 8
    told.clear()
    feed.poll()
    assert not told  # nothing changed, nobody is bothered


def test_a_cut_file_is_shown_up_to_the_cut_and_said_so(tmp_path):
    raw = _lines(_talker_first_trace())
    cut = raw.index(b'"ev": "tcpros.frame"') + 10
    whole = raw[:cut].rindex(b"\n") + 1
    path = tmp_path / "cut.jsonl"
    path.write_bytes(raw[:cut])
    feed = _feed(path)
    feed.poll()
    assert _status(feed)["problems"] == []  # a line being written, for now
    feed.clock.now += wiretrace.CUT_AFTER
    feed.poll()
    (problem,) = _status(feed)["problems"]
    assert problem == (f"{path} ends in the middle of an event (line 14, byte {whole}): the file "
                       "was cut, or the process writing it stopped mid-line; showing the 13 "
                       "events before it")
    assert any(s["what"] == "header" for s in _steps(feed))
    # the writer finishes the line after all: the problem goes
    path.write_bytes(raw)
    feed.poll()
    assert _status(feed)["problems"] == []
    assert any(s["text"].startswith("message 1") for s in _steps(feed))


def test_a_file_that_is_not_a_trace_or_turns_bad_is_named_with_its_line(tmp_path):
    foreign = tmp_path / "notes.jsonl"
    foreign.write_text("dear diary\n")
    bad = tmp_path / "bad.jsonl"
    good = _talker_first_trace()[:4]
    bad.write_bytes(_lines(good) + b'{"t": 1}\n' + _lines(good))
    feed = _feed(foreign, bad)
    feed.poll()
    assert _status(feed)["problems"] == [
        f"{foreign} is not a minros trace: line 1: the line is not JSON (a trace is written by "
        "MINROS_TRACE=FILE or 'minros trace -o FILE -- COMMAND')",
        f"{bad} stops at line 5 (byte {len(_lines(good))}): the line is not a trace event; no "
        "longer following it"]
    assert len(_steps(feed)) == 1  # registerPublisher, read before the bad line


def test_an_event_the_readers_cannot_take_is_said_and_the_rest_shown(tmp_path):
    events = _talker_first_trace()
    odd = _ev(1000.25, 1, "/talker", "xmlrpc.call", uri="http://localhost:11311/",
              local="127.0.0.1:50001", remote="127.0.0.1:11311", n="one", method="getPid",
              args=["/talker"])
    path = tmp_path / "odd.jsonl"
    path.write_bytes(_lines(events[:3] + [odd]))
    feed = _feed(path)
    feed.poll()
    (problem,) = _status(feed)["problems"]
    assert problem.startswith("an event of the trace could not be read (ValueError: ")
    path.write_bytes(_lines(events[:3] + [odd] + events[3:]))
    feed.poll()
    assert len(_steps(feed)) == 8  # the run after it, whole


def test_an_overwritten_file_is_read_again_from_its_start(tmp_path):
    path = tmp_path / "run.jsonl"
    events = _talker_first_trace()
    path.write_bytes(_lines(events))
    follower = Follower([str(path)])
    assert len(follower.poll()) == len(events)
    later = _talker_first_trace(2000.0)[:5]  # `minros trace -o` truncates its file
    path.write_bytes(_lines(later))
    assert [e["t"] for e in follower.poll()] == [e["t"] for e in later]
    assert follower.restarts == {str(path): 1}
    feed = _feed(path)
    path.write_bytes(_lines(events))
    feed.poll()
    path.write_bytes(_lines(later))
    feed.poll()
    assert _status(feed)["notes"] == [f"{path} was overwritten 1× (a new run started): read again "
                                      "from its start"]


def test_a_file_larger_than_one_read_is_read_without_waiting(tmp_path, monkeypatch):
    monkeypatch.setattr(Follower, "CHUNK", 512)
    path = tmp_path / "big.jsonl"
    path.write_bytes(_lines(_talker_first_trace()))
    feed = _feed(path)
    polls = 1
    while feed.poll():
        polls += 1
    assert polls > 3 and len(_steps(feed)) == 8


# -- the page session ------------------------------------------------------------------------

def _next_frames(outbox) -> list:
    slot, token = outbox.get(timeout=5)
    return [json.loads(frame) for frame in slot.render(token)]


def test_the_page_gets_the_steps_then_what_changes(tmp_path):
    path = tmp_path / "run.jsonl"
    events = _talker_first_trace()
    path.write_bytes(_lines(events[:6]))
    feed = _feed(path, max_steps=3)
    feed.poll()
    page, outbox, _state = session(feed)
    page.start()
    hello = replies(outbox)[0]
    assert hello["wire"] is True and hello["wire_paths"] == [str(path)]
    page.receive(json.dumps({"op": "wire_watch"}))
    (first,) = replies(outbox)
    assert first["op"] == "wire" and first["reset"] is True and first["removed"] == []
    assert [s["step"] for s in first["steps"]] == ["0", "1"]
    assert first["status"]["files"] == [str(path)] and first["status"]["t0"] == 1000.0
    # more of the run: the feed tells the page, which gets only what is new and what went
    path.write_bytes(_lines(events))
    feed.poll()
    frames = _next_frames(outbox)  # at most WIRE_INTERVAL after the first
    assert len(frames) == 1 and "reset" not in frames[0]
    assert len(frames[0]["steps"]) == 3 and sorted(frames[0]["removed"]) == [
        s["id"] for s in first["steps"]]
    assert page.wire.sent == {s["id"] for s in frames[0]["steps"]} == set(feed.model.steps)
    page.close()
    assert feed._listeners == {}


def test_a_page_of_a_server_without_traces_is_told_how_to_start_one():
    page, outbox, _state = session()
    page.start()
    assert replies(outbox)[0]["wire"] is False
    page.receive(json.dumps({"op": "wire_watch", "id": "w"}))
    (reply,) = replies(outbox)
    assert reply["error"].startswith("this server follows no wire trace: start it with "
                                     "'minros web --trace FILE'")


def test_many_steps_go_out_in_frames_of_bounded_size(tmp_path):
    from minros.web.page import WIRE_BATCH

    model_steps = WIRE_BATCH * 2 + 10
    path = tmp_path / "calls.jsonl"
    master = "http://localhost:11311/"
    events = [_ev(1000.0, 1, "n", "process", argv=["n"], master=master)]
    for i in range(model_steps):
        events.append(_ev(1000.0 + i / 1000, 1, "/n", "xmlrpc.call", uri=master,
                          local="127.0.0.1:5", remote="127.0.0.1:11311", n=i + 1,
                          method="registerPublisher",
                          args=["/n", f"/t{i % 50}", "std_msgs/String", "http://n/"],
                          reply=[1, "ok", []]))
    path.write_bytes(_lines(events))
    feed = _feed(path)
    feed.poll()
    page, outbox, _state = session(feed)
    page.receive(json.dumps({"op": "wire_watch"}))
    frames = replies(outbox)
    assert [len(f["steps"]) for f in frames] == [WIRE_BATCH, WIRE_BATCH, 10]
    assert frames[0]["reset"] and "status" not in frames[0] and "status" in frames[-1]


_KINDS = ["process", "node", "xmlrpc.call", "xmlrpc.serve", "tcp.open", "tcpros.header",
          "tcpros.frame", "tcp.data", "tcp.eof", "tcp.close"]
_VALUES = st.one_of(st.none(), st.booleans(), st.integers(-3, 70000), st.text(max_size=12),
                    st.lists(st.text(max_size=6), max_size=4),
                    st.lists(st.lists(st.text(max_size=6), max_size=3), max_size=3))
_KEYS = ["conn", "side", "local", "remote", "dir", "off", "len", "n", "fields", "head", "ok",
         "msg", "method", "args", "reply", "fault", "error", "uri", "t_reply", "topic", "name",
         "master", "argv"]


@settings(max_examples=60, deadline=None)
@given(st.lists(st.tuples(st.sampled_from(_KINDS), st.integers(1, 3),
                          st.dictionaries(st.sampled_from(_KEYS), _VALUES, max_size=8)),
                max_size=30))
def test_whatever_a_trace_holds_the_feed_goes_on(tmp_path_factory, events):
    """Events of the right shape with fields of any type: the feed says what it could not read
    and keeps following; nothing escapes its thread."""
    path = tmp_path_factory.mktemp("fuzz") / "t.jsonl"
    lines = [{"t": 1000.0 + i, "pid": pid, "node": "/n", "ev": kind, **fields}
             for i, (kind, pid, fields) in enumerate(events)]
    path.write_bytes(_lines(lines))
    feed = _feed(path)
    feed.poll()
    json.dumps(feed.changes(0, []))
