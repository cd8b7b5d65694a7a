"""The page's Wire view in a real browser (Debian's chromium driven by Playwright), on a traced
run: minros core, a listener and a talker, each under ``minros trace`` with its own file in one
directory, and ``minros web --trace DIRECTORY`` started before the nodes, so the page sees the
sequence arrive live. The steps are checked against the values the traces themselves hold
(URIs, the TCPROS port, md5sum, the first message); the screenshot is ``wire.png``.

Bad input: a trace file that does not exist (yet), one cut in the middle of a line and one
that is no trace: the view says so, and the server keeps serving the page.
"""

from __future__ import annotations

import json
import shutil
from pathlib import Path

import page_support
from page_support import Page, browser_fixture, shots_fixture, system_fixture

from support import EXAMPLES, PYTHON, free_port, wait_until

STRING_MD5 = "992ce8a1687cec8c8bd883ec73ca41d1"


def _traced(out: Path, argv: list) -> list:
    return [PYTHON, "-m", "minros", "trace", "-o", str(out), "--messages", "--", *argv]


def _events(path: Path) -> list:
    return [json.loads(line) for line in path.read_text().splitlines()]


class Run(page_support.System):
    """The traced core, the web server following the trace directory, then the nodes."""

    def __init__(self, tmp: Path) -> None:
        self.traces = tmp / "traces"
        self.traces.mkdir()
        # the Wire view shows TCPROS (a minros pair of one host would take shared memory)
        super().__init__(tmp, {"MINROS_SHM": "0"})

    def up(self) -> None:
        self.start_core(lambda argv: _traced(self.traces / "core.jsonl", argv))
        self.start_web("--trace", str(self.traces))


run = system_fixture(Run, "page_wire")
browser = browser_fixture(after="run")
shots = shots_fixture()


def _section(page: Page, name: str):
    return page.view("wire").locator(f'.wire-section[data-section="{name}"]')


def _lines(section) -> list:
    """Each visible step of a section as (its step numbers, its text)."""
    return section.locator(".wire-step").evaluate_all(
        "(els) => els.map((li) => [[...li.querySelectorAll('.wire-no')].map((n) => n.textContent),"
        " li.innerText])")


def _find(lines: list, *needles: str, start: int = 0) -> int:
    for i in range(start, len(lines)):
        if all(needle in lines[i][1] for needle in needles):
            return i
    raise AssertionError(f"no step with {needles} after {start}:\n" +
                         "\n".join(f"{n} {t}" for n, t in lines))


def test_wire_view_shows_the_sequence_of_a_traced_run_live(run, browser, shots):
    tab = Page(browser, run, shots)
    try:
        tab.open("wire")
        wire = tab.view("wire")
        wire.locator(".wire-source", has_text="core.jsonl").wait_for(timeout=15_000)
        # the listener first: the master then announces the talker with publisherUpdate
        listener = run.start(_traced(run.traces / "listener.jsonl", [
            PYTHON, str(EXAMPLES / "talker_listener/listener.py")]))
        chatter = _section(tab, "topic /chatter")
        chatter.get_by_text("registerSubscriber(").first.wait_for(timeout=20_000)  # pushed live
        talker = run.start(_traced(run.traces / "talker.jsonl", [
            PYTHON, str(EXAMPLES / "talker_listener/talker.py"), "_rate:=10"]))
        listener.read_until("I heard", 30)
        # the first three messages of a connection are shown (as minros trace show does)
        chatter.get_by_text("message 3:").first.wait_for(timeout=20_000)

        # the values of this run, from the traces themselves
        talker_events = _events(run.traces / "talker.jsonl")
        listener_events = _events(run.traces / "listener.jsonl")
        talker_uri = next(e["uri"] for e in talker_events if e["ev"] == "node")
        listener_uri = next(e["uri"] for e in listener_events if e["ev"] == "node")
        tcpros_port = next(int(e["local"].rsplit(":", 1)[1]) for e in talker_events
                           if e["ev"] == "tcp.open" and e["side"] == "accept")
        first = next(e["msg"]["data"] for e in talker_events
                     if e["ev"] == "tcpros.frame" and e.get("topic") == "/chatter")

        assert "[std_msgs/String]" in chatter.locator(".wire-title").inner_text()
        lines = _lines(chatter)
        i = _find(lines, "/listener -> /master", 'registerSubscriber("/listener", "/chatter", '
                  f'"std_msgs/String", "{listener_uri}")')
        assert lines[i][0][0] == "[1]"
        i = _find(lines, "/talker -> /master",
                  f'registerPublisher("/talker", "/chatter", "std_msgs/String", "{talker_uri}")',
                  f'["{listener_uri}"]', start=i + 1)
        assert lines[i][0][0] == "[0]"
        i = _find(lines, "/master -> /listener",
                  f'publisherUpdate("/master", "/chatter", ["{talker_uri}"])', start=i + 1)
        assert lines[i][0][0] == "[2]"
        i = _find(lines, "/listener -> /talker",
                  'requestTopic("/listener", "/chatter", [["TCPROS"]])',
                  f'["TCPROS", "localhost", {tcpros_port}]', start=i + 1)
        assert lines[i][0] == ["[3]", "[4]"]  # the call and its answer
        request_topic = i
        i = _find(lines, "TCP connection", f":{tcpros_port}", start=i + 1)
        assert lines[i][0] == ["[5]"]
        i = _find(lines, "/listener -> /talker", "connection header", "callerid=/listener",
                  f"md5sum={STRING_MD5}", "message_definition=string data", start=i + 1)
        assert lines[i][0] == ["[5]"]
        subscriber_header = i
        i = _find(lines, "/talker -> /listener", "connection header", "callerid=/talker",
                  "latching=0", start=i + 1)
        assert lines[i][0] == ["[5]"]
        i = _find(lines, "/talker -> /listener", "message 1: length prefix", start=i + 1)
        assert lines[i][0] == ["[6]"]
        assert json.dumps({"data": first}) in lines[i][1]

        # a step opens to its details: the call's arguments by name and its [code, status,
        # value], a header as a key=value table
        steps = chatter.locator(".wire-step")
        steps.nth(request_topic).locator(".wire-line").first.click()
        details = steps.nth(request_topic).locator(".wire-details")
        details.wait_for()
        text = details.inner_text()
        for needle in ("caller_id", '"/listener"', "topic", "protocols", "code", "status",
                       f'["TCPROS","localhost",{tcpros_port}]'):
            assert needle in text, text
        steps.nth(request_topic).locator(".wire-line").first.click()
        details.wait_for(state="detached")
        steps.nth(subscriber_header).locator(".wire-line").click()
        header = steps.nth(subscriber_header).locator(".wire-header")
        header.wait_for()
        rows = dict(header.locator("tr").evaluate_all(
            "(trs) => trs.map((tr) => [tr.querySelector('th').textContent,"
            " tr.querySelector('td code').textContent])"))
        assert rows["callerid"] == "/listener" and rows["md5sum"] == STRING_MD5
        assert rows["type"] == "std_msgs/String" and rows["message_definition"] == "string data\n"
        tab.page.wait_for_timeout(300)
        tab.shot("wire")

        # filtered by node: only what /talker sends or receives
        everything = len(lines)
        wire.locator(".wire-node-select").select_option("/talker")
        tab.page.wait_for_function(
            "document.querySelectorAll('.wire-section[data-section=\"topic /chatter\"] .wire-step')"
            f".length < {everything}")
        shown = _lines(chatter)
        assert not any("registerSubscriber(" in text for _n, text in shown)
        assert any("registerPublisher(" in text for _n, text in shown)
        wire.locator(".wire-node-select").select_option("")
        # and by topic or service: the section alone
        wire.locator(".wire-section-select").select_option("topic /chatter")
        tab.page.wait_for_function(
            "[...document.querySelectorAll('.wire-section')].filter((s) => !s.hidden).length === 1")
        wire.locator(".wire-section-select").select_option("")

        # paused, the list stays as it is; what arrives is counted, then shown on resume
        wire.locator(".wire-pause").click()
        tab.js("new Promise((done) => requestAnimationFrame(() => requestAnimationFrame(done)))")
        before = chatter.locator(".wire-step").count()
        echo = run.start([PYTHON, "-m", "minros", "topic", "echo", "-n", "3", "/chatter"])
        echo.read_until("hello world", 30)
        tab.page.wait_for_function("minrosPage.views.get('wire').state.missed > 0", timeout=15_000)
        assert chatter.locator(".wire-step").count() == before
        assert "new while paused" in wire.locator(".counts").inner_text()
        wire.locator(".wire-pause").click()
        tab.page.wait_for_function(
            "document.querySelectorAll('.wire-section[data-section=\"topic /chatter\"] .wire-step')"
            f".length > {before}")
        # the second subscriber's connection is told apart from the first
        assert chatter.get_by_text("#2 connection header").count() >= 1
        talker.stop()
        listener.stop()
    finally:
        tab.close()


def test_wire_view_on_a_phone(run, browser, shots):
    tab = Page(browser, run, shots, width=390, height=844)
    try:
        tab.open("wire")
        chatter = _section(tab, "topic /chatter")
        chatter.locator('.wire-step[data-step="3"]').first.wait_for(timeout=20_000)
        assert tab.js("document.documentElement.scrollWidth") <= 390  # nothing wider than the phone
        chatter.locator('.wire-step[data-what="header"]').first.locator(".wire-line").click()
        chatter.locator(".wire-header").wait_for()
        assert tab.js("document.documentElement.scrollWidth") <= 390
        box = tab.js("document.querySelector('.wire-header').getBoundingClientRect().right")
        assert box <= 390
        tab.shot("phone_wire")
    finally:
        tab.close()


def test_missing_cut_and_foreign_trace_files_are_reported_and_the_server_keeps_going(
        run, browser, shots, tmp_path):
    raw = (run.traces / "core.jsonl").read_bytes()
    cut = tmp_path / "cut.jsonl"
    lines = raw.split(b"\n")
    cut.write_bytes(b"\n".join(lines[:12]) + b"\n" + lines[12][:len(lines[12]) // 2])
    foreign = tmp_path / "notes.jsonl"
    foreign.write_text("these are my notes\n")
    missing = tmp_path / "later.jsonl"
    web_port = free_port()
    web = run.start([PYTHON, "-m", "minros", "web", "--port", str(web_port), "--trace",
                     str(missing), str(cut), str(foreign), "__name:=web_bad_traces"])
    web.read_until("listening on", timeout=30)

    class Where:
        url = f"http://127.0.0.1:{web_port}/"

    tab = Page(browser, Where(), shots)
    try:
        tab.open("wire")
        problems = tab.view("wire").locator(".wire-problems")
        problems.get_by_text(f"{missing} does not exist (yet): waiting for it").wait_for(
            timeout=15_000)
        problems.get_by_text(f"{foreign} is not a minros trace: line 1: the line is not JSON"
                             ).wait_for()
        whole = sum(len(line) + 1 for line in lines[:12])
        problems.get_by_text(f"{cut} ends in the middle of an event (line 13, byte {whole})"
                             ).wait_for(timeout=15_000)
        # what the cut file holds before the cut is shown
        assert tab.js("minrosPage.views.get('wire').state.steps") > 0
        # the server still serves: the graph is read, the missing file is followed once it exists
        assert web.alive()
        assert tab.js("minrosPage.graph.version") > 0
        shutil.copy(run.traces / "talker.jsonl", missing)
        _section(tab, "topic /chatter").get_by_text("registerPublisher(").first.wait_for(
            timeout=15_000)
        wait_until(lambda: problems.get_by_text("does not exist").count() == 0, 10,
                   what="the missing file's problem to go")
        tab.shot("wire_bad_files")
    finally:
        tab.close()
        web.stop()
