"""The page's Learn view in a real browser (Debian's chromium driven by Playwright): a learner
lists the exercises, picks the first, starts it from the page (the server starts what ``minros
learn 1`` starts: a master and a talker, each traced into the exercise's folder), does what the
task says in "another terminal" (the traced ``minros topic echo`` the task prints), sees the
trace of the folder as the Wire view's numbered sequence, answers wrong (the hint is shown),
then right, and stops it: every process the start ran is gone. Closing the page stops an
exercise too, after the grace a reload gets (a reload keeps it). Screenshots: ``learn.png``,
``learn_not_yet.png``, ``phone_learn.png``.
"""

from __future__ import annotations

import json
import os
import subprocess
from pathlib import Path

import page_support
from page_support import Page, browser_fixture, shots_fixture, system_fixture

from minros import learn
from minros.web.learning import OWNER_GRACE
from support import PYTHON, wait_until
from zenoh_support import require_zenoh


def _alive(pid: int) -> bool:
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    return True


def _left_in(folder: Path) -> list:
    """Processes whose working directory is in ``folder`` (an exercise's nodes run there)."""
    found = []
    for entry in Path("/proc").iterdir():
        if not entry.name.isdigit():
            continue
        try:
            cwd = os.readlink(entry / "cwd")
        except OSError:
            continue
        if cwd == str(folder) or cwd.startswith(str(folder) + "/"):
            found.append((int(entry.name), (entry / "cmdline").read_bytes().replace(b"\0", b" ")))
    return found


class Server(page_support.System):
    """A master for the server's own node, and ``minros web`` keeping exercises in ``learn``."""

    def __init__(self, tmp: Path, option: bool = False) -> None:
        """``option``: the folder named by ``--learn-dir``, which wins over $MINROS_LEARN_DIR."""
        self.base = tmp / "learn"
        self.option = option
        super().__init__(tmp, {"MINROS_LEARN_DIR": str(tmp / "not_here" if option else self.base)})

    def up(self) -> None:
        self.start_core()
        self.start_web(*(["--learn-dir", str(self.base)] if self.option else []))

    def facts(self, number: int) -> dict:
        folder = next(self.base.glob(f"{number:02d}-*"))
        return json.loads((folder / "state.json").read_text())

    def check_stopped(self, output: str) -> None:
        super().check_stopped(output)
        assert not _left_in(self.base), "minros web left an exercise's processes behind"


server = system_fixture(Server, "page_learn")
browser = browser_fixture(after="server")
shots = shots_fixture()


def _running(view, number: int, timeout: float = 60_000) -> None:
    view.page.wait_for_function(
        "(n) => { const s = minrosPage.views.get('learn').state;"
        " return s.run && s.run.number === n && s.run.state === 'running'; }",
        arg=number, timeout=timeout)


def test_a_learner_starts_exercise_1_answers_wrong_then_right_and_stops_it(server, browser, shots):
    tab = Page(browser, server, shots)
    try:
        tab.open("learn")
        view = tab.view("learn")
        items = view.locator(".learn-item")
        items.nth(len(learn.exercises()) - 1).wait_for(timeout=15_000)
        assert items.count() == len(learn.exercises())
        assert items.nth(0).inner_text().split("\n")[:2] == [
            "1", "The master's answer to registerSubscriber"]
        view.locator('.learn-item[data-number="1"]').click()
        task = view.locator(".learn-task")
        assert "ROS_MASTER_URI=<master>" in task.inner_text()  # a preview until it starts
        assert "Start runs master, talker" in view.locator(".learn-state").inner_text()

        view.locator(".learn-start").click()
        _running(tab, 1)
        facts = server.facts(1)
        pids = list(facts["pids"].values())
        assert len(pids) == 2 and all(_alive(pid) for pid in pids)
        state = view.locator(".learn-state").inner_text()
        assert f"master (pid {facts['pids']['master']})" in state
        assert f"talker (pid {facts['pids']['talker']})" in state
        assert f"ROS_MASTER_URI={facts['master']}" in task.inner_text()  # the start's facts
        folder = Path(facts["dir"])
        assert folder.parent == server.base

        # the folder's trace, as the Wire view's numbered sequence: the talker registered
        chatter = view.locator('.learn-trace .wire-section[data-section="topic /chatter"]')
        chatter.get_by_text('registerPublisher("/talker", "/chatter"').wait_for(timeout=20_000)

        # the learner, in another terminal: source env.sh, then the traced command of the task
        env = dict(server.env)
        for line in (folder / "env.sh").read_text().splitlines():
            if line.startswith("export "):
                key, _, value = line[len("export "):].partition("=")
                env[key] = value
        assert env["ROS_MASTER_URI"] == facts["master"]
        done = subprocess.run([PYTHON, "-m", "minros", "trace", "-o", facts["me"], "--",
                               PYTHON, "-m", "minros", "topic", "echo", "-n", "1", "/chatter"],
                              env=env, capture_output=True, text=True, timeout=60, cwd=folder)
        assert done.returncode == 0 and "hello world" in done.stdout, done.stderr
        # what the learner did shows up in the trace: registerSubscriber answered [1] [2]
        mine = chatter.locator(".wire-step", has_text='registerSubscriber("/rostopic')
        mine.first.wait_for(timeout=20_000)
        talker = next(json.loads(line)["uri"] for line in
                      (folder / "talker.jsonl").read_text().splitlines()
                      if json.loads(line)["ev"] == "node")
        assert f'["{talker}"]' in mine.first.inner_text()

        # wrong: the master's own URI; the hint says where to look
        answer = view.locator(".learn-answer")
        answer.fill(facts["master"])
        view.locator(".learn-check").click()
        verdict = view.locator(".learn-verdict.not-yet")
        verdict.wait_for(timeout=20_000)
        text = verdict.inner_text()
        assert "Not yet:" in text and "is the master itself" in text, text
        assert "Hint: The answer to registerSubscriber [2] names the publishers." in text
        tab.shot("learn_not_yet")
        # right: the talker's URI, from the answer the master gave
        answer.fill(talker)
        answer.press("Enter")
        right = view.locator(".learn-verdict.right")
        right.wait_for(timeout=20_000)
        assert right.inner_text().startswith("Right.") and talker in right.inner_text()
        assert view.locator(".learn-hint").count() == 0
        tab.page.wait_for_timeout(300)
        tab.shot("learn")
        # minros learn 1 in a terminal meanwhile is refused, and told where this one stops
        again = subprocess.run([PYTHON, "-m", "minros", "learn", "1", "--dir", str(server.base)],
                               env=server.env, capture_output=True, text=True, timeout=60)
        assert again.returncode == 1 and again.stderr.strip().endswith(
            f"is already running (pid {server.web.pid}): stop it in the Learn view of minros "
            "web's page first (it started it)"), again.stderr
        assert all(_alive(pid) for pid in pids)

        # stopped from the page: every process it started ends, none is left in its folder
        view.locator(".learn-stop").click()
        tab.page.wait_for_function("minrosPage.views.get('learn').state.run.state === 'stopped'",
                                   timeout=30_000)
        assert "stopped (stopped from the page)" in view.locator(".learn-state").inner_text()
        assert not [pid for pid in pids if _alive(pid)]
        assert not _left_in(folder)
        assert view.locator(".learn-start").inner_text() == "Start again"
        # the answer can still be checked against the traces left in the folder
        answer.fill(talker)
        view.locator(".learn-check").click()
        tab.page.wait_for_function("!document.querySelector('.learn-check').disabled")
        assert view.locator(".learn-verdict.right").count() == 1
    finally:
        tab.close()


def test_exercise_11_starts_from_the_page_through_minros_zenoh(server, browser, shots):
    require_zenoh()
    tab = Page(browser, server, shots)
    try:
        tab.open("learn")
        view = tab.view("learn")
        view.locator('.learn-item[data-number="11"]').click()
        assert "Start runs master, master_b, talker, bridge_a, bridge_b" in view.locator(
            ".learn-state").inner_text()
        view.locator(".learn-start").click()
        _running(tab, 11, timeout=90_000)
        facts = server.facts(11)
        assert facts["variant"] == "zenoh"
        pids = list(facts["pids"].values())
        assert len(pids) == 5 and all(_alive(pid) for pid in pids)
        task = view.locator(".learn-task").inner_text()
        assert f"listens on tcp/127.0.0.1:{facts['zenoh_port']}" in task
        # master B's trace, in the view: the bridge there registered /chatter as a publisher
        chatter = view.locator('.learn-trace .wire-section[data-section="topic /chatter"]')
        chatter.get_by_text('registerPublisher("/minros_zenoh", "/chatter"').first.wait_for(
            timeout=20_000)
        env = dict(server.env, ROS_MASTER_URI=facts["master_b"], ROS_HOSTNAME="localhost")
        done = subprocess.run([PYTHON, "-m", "minros", "trace", "-o", facts["me"], "--",
                               PYTHON, "-m", "minros", "topic", "echo", "-n", "1", "/chatter"],
                              env=env, capture_output=True, text=True, timeout=60,
                              cwd=facts["dir"])
        assert done.returncode == 0 and "hello world" in done.stdout, done.stderr
        keys = subprocess.run([PYTHON, "-m", "minros", "zenoh", "keys", "/chatter"], env=env,
                              capture_output=True, text=True, timeout=60)
        assert keys.returncode == 0, keys.stderr
        answer = view.locator(".learn-answer")
        answer.fill(f"/minros_zenoh {keys.stdout.strip()}")
        view.locator(".learn-check").click()
        right = view.locator(".learn-verdict.right")
        right.wait_for(timeout=20_000)
        assert "callerid=/minros_zenoh" in right.inner_text()
        tab.page.wait_for_timeout(300)
        tab.shot("learn_zenoh")
        view.locator(".learn-stop").click()
        tab.page.wait_for_function("minrosPage.views.get('learn').state.run.state === 'stopped'",
                                   timeout=40_000)
        assert not [pid for pid in pids if _alive(pid)]
        assert not _left_in(Path(facts["dir"]))
    finally:
        tab.close()


def test_a_reload_keeps_the_exercise_and_closing_the_page_stops_it(server, browser, shots):
    tab = Page(browser, server, shots, width=390, height=844)
    try:
        tab.open("learn")
        view = tab.view("learn")
        view.locator('.learn-item[data-number="7"]').click()
        view.locator(".learn-start").click()
        _running(tab, 7)
        facts = server.facts(7)
        pids = list(facts["pids"].values())
        assert len(pids) == 3 and all(_alive(pid) for pid in pids)
        # a reload: the page claims its exercise back with the id it kept
        tab.page.reload()
        tab.page.wait_for_function("minrosPage.conn.state === 'connected'", timeout=20_000)
        tab.page.wait_for_function(
            "(() => { const r = minrosPage.views.get('learn').state.run;"
            " return r && r.number === 7 && r.mine && r.state === 'running'; })()",
            timeout=20_000)
        assert view.locator(".learn-stop").is_enabled()
        assert view.locator(".learn-item.selected").get_attribute("data-number") == "7"
        view.locator('.learn-trace .wire-section[data-section="topic /door"]').wait_for(
            timeout=20_000)
        assert tab.js("document.documentElement.scrollWidth") <= 390  # nothing wider than a phone
        tab.shot("phone_learn")
        assert all(_alive(pid) for pid in pids)
    finally:
        tab.close()  # the page closes: its exercise stops after the grace
    wait_until(lambda: not any(_alive(pid) for pid in pids), OWNER_GRACE + 30,
               what="the closed page's exercise to stop")
    assert not _left_in(Path(facts["dir"]))


def test_the_server_stopping_stops_the_exercise(browser, shots, tmp_path):
    own = Server(tmp_path, option=True)  # a server of its own (this test stops it), --learn-dir
    try:
        tab = Page(browser, own, shots)
        try:
            tab.open("learn")
            view = tab.view("learn")
            view.locator('.learn-item[data-number="2"]').click()
            view.locator(".learn-start").click()
            _running(tab, 2)
            facts = own.facts(2)  # in --learn-dir's folder, not $MINROS_LEARN_DIR's
            assert Path(facts["dir"]).parent == own.base and not (tmp_path / "not_here").exists()
            pids = list(facts["pids"].values())
            assert all(_alive(pid) for pid in pids)
            out = own.web.stop(timeout=30)  # Ctrl-C: the server stops what the page started
            assert "exercise 2 stopped: the server stopped" in out, out[-2000:]
            assert not [pid for pid in pids if _alive(pid)]
            assert not _left_in(Path(facts["dir"]))
            tab.page.wait_for_function("minrosPage.conn.state !== 'connected'", timeout=20_000)
        finally:
            tab.errors.clear()  # the page's reconnection attempts, to a server that is gone
            tab.close()
    finally:
        own.stop()
