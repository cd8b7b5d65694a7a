"""The page's Learn view, server side, without a browser: the ops of :mod:`minros.web.learning`
through a page session. A fake runner stands for ``minros learn``'s (its processes are objects
that end when stopped, its folder gets a trace the Wire view's feed follows), so the rules are
checked without starting programs: one exercise at a time, only its page stops it, a closed
page's exercise stops after the grace unless the page comes back with the run's id, the time
limit, a process that ends, pages not of this machine, bad input. Exercise 5 starts nothing,
so the real runner and checker are used for it: a wrong md5sum gets its hint, the right one
passes."""

from __future__ import annotations

import json
import threading
import time

import pytest
from test_trace import _talker_first_trace, _write
from test_web_page import session

from minros import learn
from minros.learn.catalog import md5_variants
from minros.learn.session import Runner, folder_for
from minros.web.learning import NO_TRACE, LearnHub
from minros.web.origin import OriginPolicy


class FakeProc:
    def __init__(self, pid: int) -> None:
        self.pid = pid
        self.returncode = None

    def poll(self):
        return self.returncode


class FakeRunner:
    """What LearnHub uses of minros learn's Runner: start (a folder with state.json and a
    trace), the processes, stop."""

    made: list = []
    log: list = []
    hold = False  # start waits until the test opens its gate
    too_big_text = ""  # what too_big says: "" while the traces may grow

    def __init__(self, exercise, base, variant="", say=print, stop_hint="") -> None:
        if variant and variant not in exercise.variants:
            raise LookupError(f"no variant {variant}")
        self.exercise = exercise
        self.variant = variant or exercise.default_variant
        self.folder = folder_for(base, exercise)
        self.procs: dict = {}
        self.gate = threading.Event()
        if not FakeRunner.hold:
            self.gate.set()
        self.stopped = threading.Event()
        FakeRunner.made.append(self)

    def start(self):
        self.gate.wait(10)
        FakeRunner.log.append(("start", self.exercise.number))
        self.folder.mkdir(parents=True, exist_ok=True)
        _write(self.folder / "master.jsonl", _talker_first_trace())
        facts = {"number": self.exercise.number, "dir": str(self.folder), "port": 11311,
                 "master": "http://localhost:11311/", "me": str(self.folder / "me.jsonl")}
        (self.folder / "state.json").write_text(json.dumps(facts))
        for i, process in enumerate(self.exercise.processes(self.variant)):
            self.procs[process.name] = FakeProc(1000 + i)
        return facts

    def too_big(self):
        return FakeRunner.too_big_text

    def stop(self):
        FakeRunner.log.append(("stop", self.exercise.number))
        for proc in self.procs.values():
            if proc.returncode is None:
                proc.returncode = -2
        self.stopped.set()


@pytest.fixture
def hub(tmp_path):
    FakeRunner.made, FakeRunner.log, FakeRunner.hold = [], [], False
    FakeRunner.too_big_text = ""
    made = LearnHub(tmp_path / "learn", runner=FakeRunner, grace=0.3)
    yield made
    made.close()


def frames(outbox, op: str, until, timeout: float = 10.0) -> dict:
    """The ``op`` frames a page is sent, until one satisfies ``until``; that one."""
    deadline = time.monotonic() + timeout
    seen = []
    while time.monotonic() < deadline:
        got = outbox.get(timeout=0.2)
        if got is None:
            continue
        slot, item = got
        rendered = item if slot is None else slot.render(item)
        for text in [rendered] if isinstance(rendered, (str, bytes)) else rendered:
            frame = json.loads(text)
            seen.append(frame)
            if frame.get("op") == op and until(frame):
                return frame
    raise AssertionError(f"no {op} frame as wanted within {timeout} s; sent: {seen[-10:]}")


def run_state(state: str):
    return lambda frame: frame["run"] is not None and frame["run"]["state"] == state


def send(page, **msg) -> None:
    page.receive(json.dumps(msg))


# -- the list --------------------------------------------------------------------------------

def test_the_list_names_every_exercise_with_its_form_what_it_starts_and_a_preview(hub):
    page, outbox, _state = session(learn=hub)
    page.start()
    hello = frames(outbox, "hello", lambda f: True)
    assert hello["learn"] is True
    send(page, op="learn_list", id="l")
    reply = frames(outbox, "reply", lambda f: f["id"] == "l")
    listed = reply["exercises"]
    assert [e["number"] for e in listed] == [ex.number for ex in learn.exercises()]
    assert len(listed) >= 10 and reply["folder"] == str(hub.base) and reply["local"] is True
    first = listed[0]
    assert first["title"] == "The master's answer to registerSubscriber"
    assert first["answer_form"] == "URI..." and first["processes"] == ["master", "talker"]
    # what only a start decides is left as <name>; the folder is the server's
    assert "ROS_MASTER_URI=<master>" in first["preview"]
    assert f"{hub.base}/01-register-subscriber/me.jsonl" in first["preview"]
    eleven = listed[10]
    assert eleven["variants"] == ["zenoh", "relay"]
    # a start without a variant (the page's) runs the first that can start here
    assert eleven["variant"] == learn.exercise(11).default_variant
    assert eleven["answer_form"] == learn.exercise(11).form()
    if eleven["variant"] == "zenoh":
        assert eleven["planned"] == {} and "bridge_a" in eleven["processes"]
        assert "key expression" in eleven["preview"]
    else:  # without eclipse-zenoh: why, in the about line
        assert "pip install minros[zenoh]" in eleven["planned"]["zenoh"]
    assert listed[4]["processes"] == []  # the md5sum is worked out by hand


# -- start, watch, stop ----------------------------------------------------------------------

def test_a_start_is_watched_its_folder_followed_and_its_page_stops_it(hub):
    page, outbox, _state = session(learn=hub)
    send(page, op="learn_watch")
    empty = frames(outbox, "learn", lambda f: True)
    assert empty["run"] is None
    wire = frames(outbox, "learn_wire", lambda f: True)
    assert wire["reset"] and wire["steps"] == [] and wire["status"] == NO_TRACE
    send(page, op="learn_start", id="s", number=1)
    reply = frames(outbox, "reply", lambda f: f["id"] == "s")
    assert reply["number"] == 1 and len(reply["run"]) >= 16
    running = frames(outbox, "learn", run_state("running"))["run"]
    assert running["mine"] is True and running["run"] == reply["run"]
    assert running["processes"] == [{"name": "master", "pid": 1000}, {"name": "talker", "pid": 1001}]
    assert "ROS_MASTER_URI=http://localhost:11311/" in running["task"]  # the facts filled in
    assert running["env"] == f"source {hub.base}/01-register-subscriber/env.sh"
    assert 3500 < running["remaining"] <= running["limit"] == 3600
    # the exercise's folder is followed as the Wire view follows traces: the numbered steps
    traced = frames(outbox, "learn_wire", lambda f: bool(f["steps"]))
    assert traced["reset"] and traced["status"]["specs"] == [str(FakeRunner.made[0].folder)]
    assert [s["step"] for s in traced["steps"]][:2] == ["0", "1"]
    assert traced["steps"][0]["text"].startswith('registerPublisher("/talker", "/chatter"')
    # a process that ends is said
    FakeRunner.made[0].procs["talker"].returncode = 1
    ended = frames(outbox, "learn", lambda f: len(f["run"]["processes"]) == 2 and
                   "status" in f["run"]["processes"][1])
    assert ended["run"]["processes"][1] == {"name": "talker", "pid": 1001, "status": 1}
    send(page, op="learn_stop", id="x")
    assert frames(outbox, "reply", lambda f: f["id"] == "x")["stopping"] is True
    stopped = frames(outbox, "learn", run_state("stopped"))["run"]
    assert stopped["reason"] == "stopped from the page" and stopped["remaining"] == 0
    assert FakeRunner.log == [("start", 1), ("stop", 1)]
    # stopping what is stopped is nothing
    send(page, op="learn_stop", id="y")
    assert frames(outbox, "reply", lambda f: f["id"] == "y")["stopping"] is False
    page.close()
    assert hub._watchers == {} and hub.run.feed._listeners == {}


def test_another_page_sees_the_run_but_neither_stops_it_nor_starts_another(hub):
    owner, owner_box, _ = session(learn=hub, client_id="a")
    other, other_box, _ = session(learn=hub, client_id="b")
    send(owner, op="learn_start", id="s", number=2)
    send(other, op="learn_watch")
    seen = frames(other_box, "learn", run_state("running"))["run"]
    assert seen["mine"] is False and seen["owned"] is True and "run" not in seen
    send(other, op="learn_stop", id="x")
    assert frames(other_box, "reply", lambda f: f["id"] == "x")["error"] == (
        "exercise 2 was started from another page: stop it there (or close that page)")
    send(other, op="learn_start", id="y", number=3)
    assert frames(other_box, "reply", lambda f: f["id"] == "y")["error"] == (
        "exercise 2 is running, started from another page: stop it there (or close that "
        "page) first")
    assert hub.run.number == 2 and hub.run.state == "running"
    # its own page starts another: the first is stopped before the second starts
    send(owner, op="learn_start", id="z", number=3)
    frames(other_box, "learn", lambda f: f["run"]["number"] == 3 and f["run"]["state"] == "running")
    assert FakeRunner.log == [("start", 2), ("stop", 2), ("start", 3)]
    assert FakeRunner.made[0].procs["talker"].returncode == -2
    owner.close()
    other.close()


def test_a_start_while_the_last_is_starting_is_refused(hub):
    FakeRunner.hold = True
    page, outbox, _ = session(learn=hub)
    send(page, op="learn_watch")
    send(page, op="learn_start", id="s", number=1)
    frames(outbox, "learn", run_state("starting"))
    send(page, op="learn_start", id="t", number=4)
    assert frames(outbox, "reply", lambda f: f["id"] == "t")["error"] == (
        "exercise 1 is still starting: wait a moment, then start again")
    FakeRunner.made[0].gate.set()
    frames(outbox, "learn", run_state("running"))
    assert len(FakeRunner.made) == 2 and FakeRunner.log == [("start", 1)]
    page.close()


def test_a_closed_page_s_exercise_stops_after_the_grace_unless_the_page_comes_back(hub):
    page, outbox, _ = session(learn=hub, client_id="a")
    send(page, op="learn_watch")
    send(page, op="learn_start", id="s", number=1)
    run_id = frames(outbox, "reply", lambda f: f["id"] == "s")["run"]
    frames(outbox, "learn", run_state("running"))
    page.close()  # a reload: the same tab comes back with the run's id within the grace
    again, again_box, _ = session(learn=hub, client_id="b")
    send(again, op="learn_watch", run=run_id)
    claimed = frames(again_box, "learn", lambda f: f["run"]["mine"])["run"]
    assert claimed["run"] == run_id and claimed["state"] == "running"
    time.sleep(hub.grace * 2)  # the grace passes: the exercise keeps its page
    assert hub.run.state == "running" and not FakeRunner.made[0].stopped.is_set()
    # a page that has a wrong id claims nothing
    stranger, stranger_box, _ = session(learn=hub, client_id="c")
    send(stranger, op="learn_watch", run="not-the-id")
    assert frames(stranger_box, "learn", lambda f: True)["run"]["mine"] is False
    again.close()
    assert FakeRunner.made[0].stopped.wait(5)
    assert frames(stranger_box, "learn", run_state("stopped"))["run"]["reason"] == "its page closed"
    stranger.close()


def test_an_exercise_stops_at_the_time_limit(tmp_path):
    FakeRunner.made, FakeRunner.log = [], []
    hub = LearnHub(tmp_path / "learn", runner=FakeRunner, limit=0.5)
    try:
        page, outbox, _ = session(learn=hub)
        send(page, op="learn_watch")
        send(page, op="learn_start", id="s", number=7)
        stopped = frames(outbox, "learn", run_state("stopped"))["run"]
        assert stopped["reason"] == ("stopped after 0.00833333 minutes (an exercise takes "
                                     "five; start it again)")
        assert FakeRunner.log == [("start", 7), ("stop", 7)]
        page.close()
    finally:
        hub.close()


def test_an_exercise_whose_traces_grow_too_big_stops(tmp_path):
    FakeRunner.made, FakeRunner.log, FakeRunner.too_big_text = [], [], ""
    hub = LearnHub(tmp_path / "learn", runner=FakeRunner, size_every=0.05)
    try:
        page, outbox, _ = session(learn=hub)
        send(page, op="learn_watch")
        send(page, op="learn_start", id="s", number=7)
        frames(outbox, "learn", run_state("running"))
        FakeRunner.too_big_text = "its traces in /x passed 200 MB (start it again)"
        stopped = frames(outbox, "learn", run_state("stopped"))["run"]
        assert stopped["reason"] == "its traces in /x passed 200 MB (start it again)"
        assert FakeRunner.log == [("start", 7), ("stop", 7)]
        page.close()
    finally:
        FakeRunner.too_big_text = ""
        hub.close()


def test_the_server_stopping_stops_the_exercise(hub):
    page, outbox, _ = session(learn=hub)
    send(page, op="learn_start", id="s", number=1)
    send(page, op="learn_watch")
    frames(outbox, "learn", run_state("running"))
    hub.close()  # returns once the processes are stopped
    assert FakeRunner.log == [("start", 1), ("stop", 1)] and hub.run.state == "stopped"
    assert hub.run.reason == "the server stopped"
    send(page, op="learn_start", id="t", number=1)
    assert frames(outbox, "reply", lambda f: f["id"] == "t")["error"] == "the server is stopping"
    page.close()


def test_a_failed_start_says_why(tmp_path):
    class Failing(FakeRunner):
        def start(self):
            from minros.learn.session import LearnError

            raise LearnError("talker was not ready within 30 s: see talker.log")

    hub = LearnHub(tmp_path / "learn", runner=Failing)
    try:
        page, outbox, _ = session(learn=hub)
        send(page, op="learn_watch")
        send(page, op="learn_start", id="s", number=1)
        failed = frames(outbox, "learn", run_state("failed"))["run"]
        assert failed["error"] == "talker was not ready within 30 s: see talker.log"
        page.close()
    finally:
        hub.close()


# -- bad input and pages of elsewhere ----------------------------------------------------------

@pytest.mark.parametrize("msg, op, text", [
    ({"number": 99}, "reply", "there is no exercise 99: minros learn --list shows the 11 exercises"),
    ({"number": "1"}, "status", "Expected field number to be one of ('int',). Invalid value: 1"),
    ({"number": True}, "status", "number is an exercise's number (1, 2, ...), not true or false"),
    ({}, "status", "Expected a number field but none was found."),
    ({"number": 11, "variant": "pigeon"}, "reply",
     "exercise 11 has no variant 'pigeon' (variants: zenoh, relay)"),
    ({"number": 1, "variant": "relay"}, "reply", "exercise 1 has no variant 'relay' (variants: none)"),
])
def test_a_start_the_catalog_does_not_have_is_refused_with_what_to_do(tmp_path, msg, op, text):
    hub = LearnHub(tmp_path / "learn", runner=Runner)
    page, outbox, _ = session(learn=hub)
    send(page, op="learn_start", id="s", **msg)
    got = frames(outbox, op, lambda f: f.get("id") == "s")
    said = got["error"] if op == "reply" else got["msg"].removeprefix("learn_start: ")
    assert said.startswith(text), got
    assert hub.run is None and not (tmp_path / "learn").exists()  # nothing started, no folder
    page.close()


def test_a_page_not_of_this_machine_may_watch_but_not_start_stop_or_check(hub):
    page, outbox, _ = session(learn=hub, local=False)
    page.start()
    assert frames(outbox, "hello", lambda f: True)["learn"] is False
    for op in ("learn_start", "learn_stop", "learn_check"):
        send(page, op=op, id=op, number=1, answer="x")
        status = frames(outbox, "status", lambda f, op=op: f.get("id") == op)
        assert status["msg"].startswith(f"{op}: only a page of this machine may "), status
        assert "--allow-origin" in status["msg"]
    assert hub.run is None and FakeRunner.made == []
    page.close()


def test_local_page_is_this_machine_s_pages_only():
    policy = OriginPolicy(["https://app.foxglove.dev"], ["robot", "127.0.0.1"])
    assert policy.local_page(None, "anything:1")  # not a page
    assert policy.local_page("http://localhost:3000", "localhost:9090")
    assert policy.local_page("http://127.0.0.1:9090", "127.0.0.1:9090")
    assert policy.local_page("http://robot:9090", "robot:9090")  # its own page, by its name
    assert policy.local_page("http://192.168.1.5:9090", "192.168.1.5:9090")
    # let in, but not of this machine
    assert policy.origin_error("https://app.foxglove.dev", "127.0.0.1:9090") is None
    assert not policy.local_page("https://app.foxglove.dev", "127.0.0.1:9090")
    assert not policy.local_page("null", "127.0.0.1:9090")
    assert not policy.local_page("http://robot:9091", "robot:9090")  # another port
    # '*' turns the Host check off: a name rebound to this machine is not its own page
    anything = OriginPolicy(["*"], ["robot"])
    assert anything.origin_error("http://evil.example:9090", "evil.example:9090") is None
    assert not anything.local_page("http://evil.example:9090", "evil.example:9090")
    assert anything.local_page("http://robot:9090", "robot:9090")


# -- checking, with the real runner and checker --------------------------------------------------

def test_exercise_5_starts_nothing_and_its_answer_is_checked_with_a_hint(tmp_path):
    hub = LearnHub(tmp_path / "learn", runner=Runner)
    try:
        page, outbox, _ = session(learn=hub)
        send(page, op="learn_check", id="early", number=5, answer="0" * 32)
        assert frames(outbox, "reply", lambda f: f["id"] == "early")["error"] == (
            f"exercise 5 has not been started yet: start it first (its traces go to "
            f"{tmp_path}/learn/05-md5sum)")
        send(page, op="learn_watch")
        send(page, op="learn_start", id="s", number=5)
        ready = frames(outbox, "learn", run_state("ready"))["run"]
        assert ready["processes"] == [] and "learn_msgs/Reading" in ready["task"]
        facts = json.loads((tmp_path / "learn/05-md5sum/state.json").read_text())
        assert f"float64 {facts['field']}" in ready["task"]
        md5s = md5_variants(facts)
        send(page, op="learn_check", id="wrong", number=5, answer=md5s["newline"])
        wrong = frames(outbox, "reply", lambda f: f["id"] == "wrong")
        assert wrong["ok"] is False and wrong["hint"] == "Almost: no newline at the end."
        send(page, op="learn_check", id="right", number=5, answer=f"  {md5s['right']} ")
        right = frames(outbox, "reply", lambda f: f["id"] == "right")
        assert right["ok"] is True and right["text"].startswith("Right")
        assert any("uint8 CELSIUS=0" in line for line in right["details"])
        send(page, op="learn_check", id="long", number=5, answer="x" * 5000)
        assert frames(outbox, "reply", lambda f: f["id"] == "long")["error"].startswith(
            "the answer is 5000 characters long")
        page.close()
    finally:
        hub.close()
