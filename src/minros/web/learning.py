"""The page's Learn view, server side: ``minros learn``'s exercises listed, started, watched,
checked and stopped for a page.

:class:`LearnHub` (one per server, owned by the :class:`~minros.web.page.PageHub`) holds at
most one started exercise, a :class:`LearnRun`: what ``minros learn N`` starts
(:class:`minros.learn.session.Runner`: the exercise's master and small nodes, each traced into
the exercise's folder), the wire feed that follows that folder for the page (the Wire view's
:class:`~minros.web.wiretrace.WireFeed`: the learner's own ``me*.jsonl`` traces appear in it
as they are written), the page that started it, and a thread of its own that starts, watches
and stops it. :class:`LearnSession` (one per page) adds the view's ops to the page's session:

=================  ==========================================================================
``learn_list``     reply: the exercises (number, title, minutes, the answer's form, what each
                   starts, a preview of its task) and where their folders are
``learn_watch``    ``{run?}``: ``learn`` frames (the started exercise: its state, task,
                   processes, why it stopped) now and whenever it changes, and ``learn_wire``
                   frames (its folder's trace, as the Wire view's ``wire`` frames); ``run``,
                   the id a start replied with, makes this page the exercise's page again
                   (a reload, a reconnection)
``learn_start``    ``{number, variant?}``: reply ``{run}`` at once; the start goes on in the
                   run's thread and the ``learn`` frames tell how it went
``learn_stop``     stop the started exercise (its page only, or any page once its page is gone)
``learn_check``    ``{number, answer}``: reply ``{ok, text, hint, details}``, the checker's
                   verdict on the answer against the traces of the exercise's folder
=================  ==========================================================================

What a page can make the server run is bounded as the command line bounds it, and less: a
page names an exercise by its number (and a variant the exercise has), nothing else, so only
the exercises' own programs run (``python -m minros core``, ``python -m
minros.learn.actors ROLE`` and, for exercise 11 through Zenoh, ``python -m minros zenoh`` on
loopback endpoints, all with the catalog's arguments), in the folder the server chose
(``$MINROS_LEARN_DIR``, else ``$ROS_HOME/learn``). One exercise runs at a time per server; it
stops when its page asks, when its page has been gone for :data:`OWNER_GRACE` seconds (a
reload or a reconnection within that time keeps it), after ``minros learn``'s own limits
(:data:`~minros.learn.session.RUN_LIMIT`, and its traces' size,
:data:`~minros.learn.session.TRACE_LIMIT`), and when the server stops. A page starts an
exercise's default variant unless it names another (exercise 11's is Zenoh when the
eclipse-zenoh package is installed, else the relay; the list says why a variant cannot
start). Starting, stopping and checking are for pages of this machine only
(:meth:`minros.web.origin.OriginPolicy.local_page`: no page let in only by
``--allow-origin`` starts programs here), besides the server's Host, Origin and token checks
every request passes.
"""

from __future__ import annotations

import secrets
import threading
import time
from pathlib import Path
from typing import Any, Callable, Dict, Hashable, List, Optional, Sequence

import minros
from minros import learn
from minros.learn.session import (
    RUN_LIMIT,
    SIZE_EVERY,
    STATE,
    LearnError,
    Runner,
    default_base,
    folder_for,
)
from minros.web.rosbridge import OpError, _check
from minros.web.wiretrace import WireFeed, WireWatch

#: seconds a started exercise outlives its page (a reload or a reconnection takes it back)
OWNER_GRACE = 10.0
#: how often the run's thread looks at its processes, its page and its time limit
TICK = 0.25
#: the longest answer a page may send (the longest right one is a few URIs)
MAX_ANSWER = 4000
LEARN_INTERVAL = 0.1
WIRE_INTERVAL = 0.1

#: a run's states: starting -> running (or ready: nothing to keep running) -> stopping ->
#: stopped; starting -> failed
ACTIVE = ("starting", "running", "stopping")

#: the wire status of a run whose folder is not followed yet
NO_TRACE: Dict[str, Any] = {"specs": [], "files": [], "events": 0, "t0": None, "problems": [],
                            "notes": []}


class LearnRun:
    """One start of an exercise, owned by its thread (:meth:`LearnHub._life`); the page that
    started it is ``owner`` until it goes (``orphaned`` then says since when)."""

    def __init__(self, number: int, variant: str, owner: Hashable, runner: Any,
                 deadline: float) -> None:
        self.id = secrets.token_urlsafe(12)
        self.number = number
        self.variant = variant
        self.owner: Optional[Hashable] = owner
        self.orphaned: Optional[float] = None
        self.runner = runner
        self.deadline = deadline
        self.state = "starting"
        self.task = ""
        self.error = ""
        self.reason = ""
        self.facts: Dict[str, Any] = {}
        self.ended: Dict[str, int] = {}  # process name -> exit status, once it ended
        self.feed: Optional[WireFeed] = None
        self.stop = threading.Event()
        self.stop_reason = ""
        self.thread: Optional[threading.Thread] = None

    @property
    def active(self) -> bool:
        return self.state in ACTIVE

    def processes(self) -> List[Dict[str, Any]]:
        out = []
        for name, proc in dict(self.runner.procs).items():
            entry: Dict[str, Any] = {"name": name, "pid": proc.pid}
            if name in self.ended:
                entry["status"] = self.ended[name]
            out.append(entry)
        return out


def exercise_json(ex: learn.Exercise, base: Path) -> Dict[str, Any]:
    """One exercise as the page lists it; ``preview`` is its task with what only a start
    decides (ports, URIs, the values it chooses) left as ``<name>``."""
    folder = folder_for(base, ex)
    preview = ex.task_text({"number": ex.number, "dir": str(folder),
                            "me": str(folder / "me.jsonl"), "python": "python3"})
    return {"number": ex.number, "slug": ex.slug, "title": ex.title, "minutes": ex.minutes,
            "covers": ex.covers, "answer_form": ex.form(),
            "variants": [v for v in ex.variants if v],
            "planned": {v: f"{v}: {why}" for v, why in ex.unavailable().items()},
            "variant": ex.default_variant,
            "processes": [p.name for p in ex.processes()], "folder": str(folder),
            "preview": preview}


class LearnHub:
    """The server's started exercise and the pages watching it (see the module doc).

    ``runner`` makes a :class:`~minros.learn.session.Runner` (tests give a fake), ``feed``
    a :class:`~minros.web.wiretrace.WireFeed` for a folder; a run stops after ``limit``
    seconds, or when its traces grow past the runner's bound (looked at every ``size_every``
    seconds)."""

    def __init__(self, base: Optional[Path] = None, runner: Callable[..., Any] = Runner,
                 feed: Callable[[Sequence[str]], Any] = WireFeed, grace: float = OWNER_GRACE,
                 limit: float = RUN_LIMIT, clock: Callable[[], float] = time.monotonic,
                 size_every: float = SIZE_EVERY) -> None:
        self.base = Path(base) if base is not None else default_base()
        self.make_runner = runner
        self.make_feed = feed
        self.grace = grace
        self.limit = limit
        self.size_every = size_every
        self.clock = clock
        self.run: Optional[LearnRun] = None
        self.lock = threading.Lock()
        self._watchers: Dict[Hashable, Callable[[], None]] = {}
        self._feed_watchers: Dict[Hashable, Callable[[Optional[Any]], None]] = {}
        #: held while pages are told which feed to follow, so the last told is the current
        self._feed_lock = threading.Lock()
        self._closed = False

    # -- what pages read -------------------------------------------------------------------

    def exercises(self) -> List[Dict[str, Any]]:
        return [exercise_json(ex, self.base) for ex in learn.exercises()]

    def status(self, key: Hashable) -> Optional[Dict[str, Any]]:
        """The started exercise as page ``key`` sees it (its id only for its own page)."""
        with self.lock:
            run = self.run
            if run is None:
                return None
            ex = learn.exercise(run.number)
            mine = run.owner == key
            out: Dict[str, Any] = {
                "number": run.number, "title": ex.title, "variant": run.variant,
                "state": run.state, "mine": mine, "owned": run.owner is not None,
                "task": run.task, "error": run.error, "reason": run.reason,
                "folder": str(folder_for(self.base, ex)), "processes": run.processes(),
                "limit": self.limit,
                "remaining": max(0.0, run.deadline - self.clock()) if run.active else 0.0}
            if mine:
                out["run"] = run.id
            if run.facts.get("master_b") or run.facts.get("master"):
                out["env"] = f"source {run.facts['dir']}/env.sh"
            return out

    def watch(self, key: Hashable, changed: Callable[[], None],
              feed_changed: Callable[[Optional[Any]], None], run_id: str = "") -> None:
        """Tell ``changed()`` when the run changes and ``feed_changed(feed)`` when another
        folder is followed (now too); ``run_id`` claims back a run this page started."""
        with self._feed_lock:
            with self.lock:
                self._watchers[key] = changed
                self._feed_watchers[key] = feed_changed
                run = self.run
                claimed = False
                if run is not None and run_id and secrets.compare_digest(run.id, run_id) and \
                        run.active and run.owner in (None, key):
                    claimed = run.owner is None
                    run.owner, run.orphaned = key, None
                feed = run.feed if run is not None else None
            feed_changed(feed)
        if claimed:
            self._changed()
        else:
            changed()

    def leave(self, key: Hashable) -> None:
        """Page ``key`` closed: it watches nothing, and its run, if any, is orphaned (stopped
        after the grace unless a page claims it back)."""
        orphaned = False
        with self._feed_lock, self.lock:  # no page is told of a feed after it left
            self._watchers.pop(key, None)
            self._feed_watchers.pop(key, None)
            run = self.run
            if run is not None and run.owner == key:
                run.owner, run.orphaned = None, self.clock()
                orphaned = True
        if orphaned:
            self._changed()

    # -- what pages do ---------------------------------------------------------------------

    def start(self, key: Hashable, number: int, variant: str = "") -> LearnRun:
        """Start exercise ``number`` for page ``key`` in a thread of its own (a previous run of
        this page, or of a page gone, is stopped first); LookupError or LearnError naming
        what to do when it cannot."""
        ex = learn.exercise(number)  # LookupError: there is no such exercise
        runner = self.make_runner(ex, self.base, variant=variant,
                                  say=lambda text: minros.loginfo(f"[web] learn: {text}"),
                                  stop_hint="stop it in the Learn view of minros web's page "
                                            "first (it started it)")
        with self.lock:
            if self._closed:
                raise LearnError("the server is stopping")
            previous = self.run
            if previous is not None and previous.active:
                if previous.state != "running" and previous.owner == key:
                    raise LearnError(f"exercise {previous.number} is still {previous.state}: "
                                     "wait a moment, then start again")
                if previous.owner not in (None, key):
                    raise LearnError(f"exercise {previous.number} is running, started from "
                                     "another page: stop it there (or close that page) first")
                previous.stop_reason = f"exercise {number} was started instead"
                previous.stop.set()
            run = LearnRun(number, runner.variant, key, runner, self.clock() + self.limit)
            self.run = run
            run.thread = threading.Thread(target=self._life, args=(run, previous),
                                          name=f"minros-web-learn-{number}", daemon=True)
            run.thread.start()
        self._changed()
        self._feed_to_watchers()
        return run

    def stop(self, key: Hashable) -> Optional[LearnRun]:
        """Stop the started exercise; LearnError when another (open) page started it."""
        with self.lock:
            run = self.run
            if run is None or not run.active:
                return None
            if run.owner not in (None, key):
                raise LearnError(f"exercise {run.number} was started from another page: stop "
                                 "it there (or close that page)")
            run.stop_reason = run.stop_reason or "stopped from the page"
            run.stop.set()
        return run

    def check(self, number: int, answer: str) -> Dict[str, Any]:
        """The verdict on ``answer`` from the traces of exercise ``number``'s folder
        (LookupError or LearnError naming what to do when there is nothing to check)."""
        from minros.learn.session import load_attempt

        ex = learn.exercise(number)
        folder = folder_for(self.base, ex)
        if not (folder / STATE).is_file():
            raise LearnError(f"exercise {number} has not been started yet: start it first "
                             f"(its traces go to {folder})")
        attempt = load_attempt(folder, [answer])
        result = learn.check(number, attempt.answer, attempt.traces, attempt.facts)
        return {"ok": result.ok, "text": result.text, "hint": result.hint,
                "details": list(result.details)}

    def close(self) -> None:
        """The server stops: the run is stopped, and waited for (bounded by its stop)."""
        with self.lock:
            self._closed = True
            run = self.run
            if run is not None and run.active:
                run.stop_reason = "the server stopped"
                run.stop.set()
        if run is not None and run.thread is not None:
            run.thread.join()

    # -- the run's thread ------------------------------------------------------------------

    def _life(self, run: LearnRun, previous: Optional[LearnRun]) -> None:
        if previous is not None and previous.thread is not None:
            previous.thread.join()  # its processes and folder are gone before ours start
        if run.stop.is_set():
            self._set(run, state="stopped", reason=run.stop_reason)
            return
        ex = learn.exercise(run.number)
        try:
            facts = run.runner.start()
        except LearnError as exc:
            self._set(run, state="failed", error=str(exc))
            return
        except Exception as exc:  # the runner stopped what it had started before raising
            self._set(run, state="failed", error=f"{type(exc).__name__}: {exc}")
            return
        feed = self.make_feed([str(run.runner.folder)])
        feed.start()
        minros.loginfo(f"[web] learn: exercise {run.number} started in {run.runner.folder} ("
                       + (", ".join(f"{name} pid {proc.pid}" for name, proc in
                                    run.runner.procs.items()) or "nothing to run") + ")")
        with self.lock:
            run.facts = dict(facts)
            run.task = ex.task_text(facts)
            run.feed = feed
            run.state = "running" if run.runner.procs else "ready"
        self._changed()
        self._feed_to_watchers()
        try:
            if run.runner.procs:
                run.reason = self._watch(run)
                self._set(run, state="stopping")
        finally:  # whatever happened, nothing it started outlives it
            if run.runner.procs:
                run.runner.stop()
            feed.poll()  # what was written last
            feed.stop()
        if run.state != "ready":
            minros.loginfo(f"[web] learn: exercise {run.number} stopped: {run.reason}")
            self._set(run, state="stopped")

    def _watch(self, run: LearnRun) -> str:
        """Until the run must stop: why."""
        sized = self.clock()
        while not run.stop.wait(TICK):
            now = self.clock()
            if now >= run.deadline:
                return (f"stopped after {self.limit / 60:g} minutes (an exercise takes five; "
                        "start it again)")
            if now - sized >= self.size_every:
                sized = now
                too_big = run.runner.too_big()
                if too_big:
                    return too_big
            with self.lock:
                orphaned = run.orphaned
            if orphaned is not None and now - orphaned >= self.grace:
                return "its page closed"
            ended = {name: proc.returncode for name, proc in dict(run.runner.procs).items()
                     if name not in run.ended and proc.poll() is not None}
            if ended:
                with self.lock:
                    run.ended.update(ended)
                self._changed()
        return run.stop_reason

    def _set(self, run: LearnRun, **values: Any) -> None:
        with self.lock:
            for name, value in values.items():
                setattr(run, name, value)
        self._changed()

    def _changed(self) -> None:
        with self.lock:
            watchers = list(self._watchers.values())
        for changed in watchers:
            changed()

    def _feed_to_watchers(self) -> None:
        """Tell every page which feed follows the current run's folder (None: none yet)."""
        with self._feed_lock:
            with self.lock:
                feed = self.run.feed if self.run is not None else None
                watchers = list(self._feed_watchers.values())
            for feed_changed in watchers:
                feed_changed(feed)


class LearnSession:
    """The Learn view's part of one page's session (see the module doc). ``local``: the page
    is of this machine (may start, stop and check exercises)."""

    def __init__(self, page: Any, hub: Optional[LearnHub], local: bool) -> None:
        self.page = page
        self.hub = hub
        self.local = local
        self.slot = ("page", "learn")
        self.wire_slot = ("page", "learn_wire")
        self.wire = WireWatch("learn_wire", empty_status=NO_TRACE)
        self.watching = False

    @property
    def ops(self) -> Dict[str, Callable[[Dict[str, Any]], None]]:
        return {"learn_list": self.learn_list, "learn_watch": self.learn_watch,
                "learn_start": self.learn_start, "learn_stop": self.learn_stop,
                "learn_check": self.learn_check}

    def _hub(self) -> LearnHub:
        if self.hub is None:
            raise OpError("this server runs no exercises")
        return self.hub

    def _may(self, what: str) -> LearnHub:
        hub = self._hub()
        if not self.local:
            raise OpError(f"only a page of this machine may {what}: exercises start programs "
                          "here (this page was let in by --allow-origin); open the server's "
                          "own page, or run minros learn in a terminal")
        return hub

    def learn_list(self, msg: Dict[str, Any]) -> None:
        hub = self._hub()
        self.page.reply(msg, exercises=hub.exercises(), folder=str(hub.base), local=self.local)

    def learn_watch(self, msg: Dict[str, Any]) -> None:
        _check(msg, [(False, "run", (str,))])
        hub = self._hub()
        outbox = self.page.outbox
        outbox.open_slot(self.slot, lambda _token: self._render(), maxlen=1,
                         min_interval=LEARN_INTERVAL)
        outbox.open_slot(self.wire_slot, lambda _token: self.wire.frames(), maxlen=1,
                         min_interval=WIRE_INTERVAL)
        self.watching = True
        hub.watch(self.page.key, lambda: outbox.put(self.slot, None), self._follow,
                  msg.get("run", "") if self.local else "")

    def _follow(self, feed: Optional[WireFeed]) -> None:
        """The run's folder is followed by ``feed`` now (None: none yet)."""
        old = self.wire.follow(feed)
        if old is not None and old is not feed:
            old.unlisten(self.page.key)
        if feed is not None:
            feed.listen(self.page.key, lambda: self.page.outbox.put(self.wire_slot, None))
        self.page.outbox.put(self.wire_slot, None)

    def _render(self) -> str:
        import json

        return json.dumps({"op": "learn", "run": self._hub().status(self.page.key)})

    def learn_start(self, msg: Dict[str, Any]) -> None:
        _check(msg, [(True, "number", (int,)), (False, "variant", (str,))])
        hub = self._may("start an exercise")
        number = msg["number"]
        if isinstance(number, bool):
            raise OpError("number is an exercise's number (1, 2, ...), not true or false")
        try:
            run = hub.start(self.page.key, number, msg.get("variant", ""))
        except (LookupError, LearnError) as exc:
            self.page.fail(msg, str(exc))
            return
        self.page.reply(msg, run=run.id, number=run.number)

    def learn_stop(self, msg: Dict[str, Any]) -> None:
        hub = self._may("stop an exercise")
        try:
            run = hub.stop(self.page.key)
        except LearnError as exc:
            self.page.fail(msg, str(exc))
            return
        self.page.reply(msg, stopping=run is not None)

    def learn_check(self, msg: Dict[str, Any]) -> None:
        _check(msg, [(True, "number", (int,)), (True, "answer", (str,))])
        hub = self._may("check an answer")
        answer = msg["answer"]
        if len(answer) > MAX_ANSWER:
            self.page.fail(msg, f"the answer is {len(answer)} characters long; the longest "
                                f"taken is {MAX_ANSWER} (an answer is a few words)")
            return
        number = msg["number"]

        def work() -> Dict[str, Any]:
            try:
                return hub.check(number, answer)
            except LearnError as exc:
                raise OpError(str(exc)) from None
        self.page.in_worker(msg, work)

    def close(self) -> None:
        if self.hub is not None:
            self.hub.leave(self.page.key)
        old = self.wire.follow(None)
        if old is not None:
            old.unlisten(self.page.key)
        if self.watching:
            self.page.outbox.close_slot(self.slot)
            self.page.outbox.close_slot(self.wire_slot)
