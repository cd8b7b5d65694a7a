"""Starting an exercise and reading its folder back: the I/O half of ``minros learn``.

An exercise lives in a folder of its own (``$ROS_HOME/learn/NN-slug`` unless told otherwise):
``state.json`` (the facts of this start: ports, URIs, pids, the values it chose), ``env.sh``
(what the learner sources in another terminal), the trace of every process it started
(``master.jsonl``, ``talker.jsonl``, ...) with their output (``*.log``), the files it hands
out, and the learner's own traces (``me*.jsonl``). :class:`Runner` starts and stops the
processes; :func:`load_attempt` reads a folder into what the pure checkers take.
"""

from __future__ import annotations

import json
import os
import random
import shlex
import shutil
import signal
import socket
import string
import subprocess
import sys
import threading
import time
from pathlib import Path
from typing import Any, Callable, Dict, Iterable, List, Optional

from minros import rosenv
from minros.learn.model import Attempt, Exercise, Process
from minros.wire.masterapi import MasterClient, RemoteError

__all__ = ["LearnError", "Runner", "default_base", "folder_for", "load_attempt", "read_state"]

STATE = "state.json"
#: how long one process may take to be ready (a cold start imports the message system)
READY_TIMEOUT = 30.0
#: an exercise left running stops after this long (its nodes' traces keep growing: every
#: node probes its master once a second)
RUN_LIMIT = 3600.0
#: an exercise whose folder's traces pass this many bytes stops too (five minutes of any
#: exercise write a few MB; the masters of exercise 11's zenoh variant trace the bridges'
#: graph reads, some 110 kB/s together: 200 MB in half an hour)
TRACE_LIMIT = 200 << 20
#: how often the traces' size is looked at (seconds)
SIZE_EVERY = 5.0
STOP_GRACE = (("SIGINT", 5.0), ("SIGTERM", 3.0), ("SIGKILL", 3.0))


class LearnError(Exception):
    """An expected failure, one line for the user (the text names the fix)."""


def default_base() -> Path:
    """Where exercises live: MINROS_LEARN_DIR, else ``$ROS_HOME/learn``."""
    if os.environ.get("MINROS_LEARN_DIR"):
        return Path(os.environ["MINROS_LEARN_DIR"])
    return rosenv.ros_home() / "learn"


def folder_for(base: Path, exercise: Exercise) -> Path:
    return base / f"{exercise.number:02d}-{exercise.slug}"


def _free_port() -> int:
    with socket.socket() as sock:
        sock.bind(("127.0.0.1", 0))
        return sock.getsockname()[1]


def _port_fields(processes: Iterable[Process]) -> List[str]:
    """The ``{..._port}`` fields of the processes' arguments (each start gives each a free
    port: a Zenoh endpoint, say), besides the masters' ``port`` and ``port_b``."""
    names: List[str] = []
    for process in processes:
        for arg in process.argv:
            for _text, name, _spec, _conv in string.Formatter().parse(arg):
                if name and name.endswith("_port") and name not in names:
                    names.append(name)
    return names


def _alive(pid: int) -> bool:
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except PermissionError:
        return True
    return True


def _python_command(python: str) -> str:
    """How the learner runs minros's interpreter: ``python3`` when that is it on PATH."""
    for name in ("python3", "python"):
        found = shutil.which(name)
        if found and os.path.realpath(found) == os.path.realpath(python) and \
                Path(found).parent == Path(python).parent:
            return name
    return shlex.quote(python)


def read_state(folder: Path) -> Dict[str, Any]:
    """The facts of the last start in ``folder`` (LearnError when it was never started)."""
    try:
        return json.loads((folder / STATE).read_text())
    except FileNotFoundError:
        number = folder.name.split("-", 1)[0].lstrip("0") or "N"
        raise LearnError(f"{folder} holds no started exercise: start it with minros learn "
                         f"{number} (with the same --dir)") from None
    except (OSError, ValueError) as exc:
        raise LearnError(f"cannot read {folder / STATE}: {exc}") from None


class Runner:
    """One start of an exercise: its folder, its processes, until :meth:`stop`."""

    def __init__(self, exercise: Exercise, base: Path, variant: str = "",
                 seed: Optional[int] = None, python: str = sys.executable,
                 say: Callable[[str], None] = print, stop_hint: str = "") -> None:
        if variant and variant not in exercise.variants and variant not in exercise.planned:
            known = ", ".join(v for v in exercise.variants if v) or "none"
            raise LearnError(f"exercise {exercise.number} has no variant {variant!r} "
                             f"(variants: {known})")
        missing = exercise.missing(variant) if variant else ""
        if missing:
            others = [v for v in exercise.variants if v != variant and not exercise.missing(v)]
            instead = f"; --via {others[0]} runs without it" if others else ""
            raise LearnError(f"--via {variant}: {missing}{instead}")
        self.exercise = exercise
        self.variant = variant or exercise.default_variant
        self.folder = folder_for(base, exercise)
        self.rng = random.Random(seed)
        self.python = python
        self.say = say
        self.procs: Dict[str, subprocess.Popen] = {}
        self.reported: set = set()
        self.facts: Dict[str, Any] = {}
        #: how whoever finds this start running stops it (kept in state.json)
        self.stop_hint = stop_hint or "stop it with Ctrl-C in its terminal first"

    # -- start

    def start(self) -> Dict[str, Any]:
        """Prepare the folder, start every process and wait until each is ready; returns the
        facts (also in state.json). Raises LearnError, after stopping what it started."""
        self._claim_folder()
        facts = self._facts()
        self.facts = facts
        for name, template in self.exercise.files.items():
            (self.folder / name).write_text(template.format_map(facts))
        self._write_env(facts)
        self._save()
        try:
            for process in self.exercise.processes(self.variant):
                self._start(process, facts)
                self._wait_ready(process, facts)
        except BaseException:
            self.stop()
            raise
        for process in self.exercise.processes(self.variant):
            uri = self._node_uri(process.name)
            if uri:
                facts[f"{process.name}_uri"] = uri
        master = self.procs.get("master")
        if master is not None:
            facts["master_pid"] = master.pid
        facts["pids"] = {name: proc.pid for name, proc in self.procs.items()}
        self._save()
        return facts

    def _claim_folder(self) -> None:
        if (self.folder / STATE).exists():
            try:
                old = read_state(self.folder)
            except LearnError:
                old = {}
            pid = int(old.get("runner", 0) or 0)
            if pid and pid != os.getpid() and _alive(pid) and old.get("running"):
                how = old.get("stop_hint") or "stop it with Ctrl-C in its terminal first"
                raise LearnError(f"exercise {self.exercise.number} is already running (pid "
                                 f"{pid}): {how}")
        if self.folder.exists():
            shutil.rmtree(self.folder)
        try:
            self.folder.mkdir(parents=True)
            (self.folder / "log").mkdir()
        except OSError as exc:
            raise LearnError(f"cannot create {self.folder}: {exc.strerror or exc} (--dir names "
                             "another place)") from None

    def _facts(self) -> Dict[str, Any]:
        ex = self.exercise
        facts: Dict[str, Any] = {"number": ex.number, "slug": ex.slug, "variant": self.variant,
                                 "dir": str(self.folder), "me": str(self.folder / "me.jsonl"),
                                 "python": _python_command(self.python)}
        masters = ex.masters(self.variant)
        if "a" in masters:
            facts["port"] = _free_port()
            facts["master"] = f"http://localhost:{facts['port']}/"
        if "b" in masters:
            facts["port_b"] = _free_port()
            facts["master_b"] = f"http://localhost:{facts['port_b']}/"
        for name in _port_fields(ex.processes(self.variant)):
            facts.setdefault(name, _free_port())
        if ex.choose is not None:
            facts.update(ex.choose(self.rng))
        facts.update(ex.variant_facts.get(self.variant, {}))
        if ex.slug == "md5sum":
            from minros.learn.catalog import READING_MSG

            facts["reading"] = "\n".join("    " + line for line in READING_MSG.format(
                field=facts["field"]).splitlines())
        facts["runner"] = os.getpid()
        facts["running"] = True
        facts["stop_hint"] = self.stop_hint
        return facts

    def _write_env(self, facts: Dict[str, Any]) -> None:
        master = facts.get("master_b") or facts.get("master")
        if not master:
            return
        (self.folder / "env.sh").write_text(
            f"# minros learn {facts['number']}: the learner's terminal\n"
            f"export ROS_MASTER_URI={master}\nexport ROS_HOSTNAME=localhost\n"
            "# the exercises teach TCPROS: minros nodes of one host would take shared memory\n"
            "export MINROS_SHM=0\n")

    def _save(self) -> None:
        (self.folder / STATE).write_text(json.dumps(self.facts, indent=1, sort_keys=True) + "\n")

    def _env(self, process: Process, facts: Dict[str, Any]) -> Dict[str, str]:
        env = {k: v for k, v in os.environ.items()
               if not k.startswith(("ROS_", "MINROS_")) and k != "PYTHONPATH"}
        master = facts["master_b"] if process.master == "b" else facts["master"]
        env.update(ROS_MASTER_URI=master, ROS_HOSTNAME="localhost", PYTHONUNBUFFERED="1",
                   ROS_LOG_DIR=str(self.folder / "log"),
                   # the exercises teach TCPROS, the wire every ROS 1 speaks: a minros pair
                   # on one host would otherwise take shared memory (a publisher set so
                   # answers TCPROS to any subscriber, the learner's included)
                   MINROS_SHM="0")
        if process.traced:
            env["MINROS_TRACE"] = str(self.folder / f"{process.name}.jsonl")
        return env

    def _start(self, process: Process, facts: Dict[str, Any]) -> None:
        argv = [self.python, "-m", *(arg.format_map(facts) for arg in process.argv)]
        log = open(self.folder / f"{process.name}.log", "wb")
        stdin: Any = subprocess.DEVNULL
        if process.stdin_from:
            stdin = self.procs[process.stdin_from].stdout
        try:
            proc = subprocess.Popen(argv, env=self._env(process, facts), stdin=stdin,
                                    stdout=subprocess.PIPE if process.stdout_pipe else log,
                                    stderr=log, cwd=self.folder, start_new_session=True)
        except OSError as exc:
            raise LearnError(f"cannot start {process.name}: {exc.strerror or exc}") from None
        finally:
            log.close()
        if process.stdin_from and stdin is not None:
            stdin.close()  # the reader has it now; the writer sees EPIPE when the reader ends
        self.procs[process.name] = proc

    def _wait_ready(self, process: Process, facts: Dict[str, Any]) -> None:
        deadline = time.monotonic() + READY_TIMEOUT
        proc = self.procs[process.name]
        while not self._ready(process, facts):
            if proc.poll() is not None:
                raise LearnError(f"{process.name} ended (status {proc.returncode}) before it "
                                 f"was ready: {self._tail(process.name)}")
            if time.monotonic() > deadline:
                raise LearnError(f"{process.name} was not ready within {READY_TIMEOUT:g} s: "
                                 f"{self._tail(process.name)}")
            time.sleep(0.1)

    def _tail(self, name: str) -> str:
        try:
            lines = (self.folder / f"{name}.log").read_text(errors="replace").strip().splitlines()
        except OSError:
            lines = []
        return lines[-1] if lines else f"see {self.folder / (name + '.log')}"

    def _ready(self, process: Process, facts: Dict[str, Any]) -> bool:
        if process.ready[:1] == ("master",):
            port = facts["port_b"] if process.master == "b" else facts["port"]
            master = MasterClient(f"http://127.0.0.1:{port}/", "/minros_learn", timeout=2.0)
            try:
                master.get_pid()
                return True
            except (OSError, RemoteError):  # not up yet (MasterIOError is an OSError)
                return False
            finally:
                master.close()
        if len(process.ready) != 2:
            return True
        method, name = process.ready
        if not process.traced:
            return self._registered(process, facts, method, name)
        for ev in _events(self.folder / f"{process.name}.jsonl"):
            args = ev.get("args") or []
            reply = ev.get("reply")
            if (ev.get("ev") == "xmlrpc.call" and ev.get("method") == method and len(args) > 1
                    and args[1] == name and isinstance(reply, list) and reply[:1] == [1]):
                return True
        return False

    def _registered(self, process: Process, facts: Dict[str, Any], method: str,
                    name: str) -> bool:
        """Whether the master lists ``process`` (untraced: by its node name) as ``method``
        made it: a publisher, subscriber or provider of ``name``."""
        column = {"registerPublisher": 0, "registerSubscriber": 1, "registerService": 2}
        if method not in column or not process.node:
            raise LearnError(f"{process.name} is not traced: its readiness needs its node name "
                             "and a register* call")
        port = facts["port_b"] if process.master == "b" else facts["port"]
        master = MasterClient(f"http://127.0.0.1:{port}/", "/minros_learn", timeout=2.0)
        try:
            state = master.get_system_state()
        except (OSError, RemoteError):
            return False
        finally:
            master.close()
        return any(entry[0] == name and process.node in entry[1]
                   for entry in state[column[method]])

    def _node_uri(self, name: str) -> str:
        for ev in _events(self.folder / f"{name}.jsonl"):
            if ev.get("ev") == "node" and ev.get("uri"):
                return str(ev["uri"])
        return ""

    # -- while it runs

    def wait(self, stop: threading.Event, poll: float = 0.5, limit: float = RUN_LIMIT) -> None:
        """Until ``stop`` is set or ``limit`` seconds have passed, saying once when a process
        ends (the learner may end one on purpose: exercise 10 kills the master)."""
        deadline = time.monotonic() + limit
        sized = time.monotonic()
        while not stop.wait(poll):
            now = time.monotonic()
            if now > deadline:
                self.say(f"minros learn: stopping after {limit / 60:g} minutes (an exercise "
                         "takes five; start it again with the same command)")
                return
            if now - sized >= SIZE_EVERY:
                sized = now
                too_big = self.too_big()
                if too_big:
                    self.say(f"minros learn: stopping: {too_big}")
                    return
            for name, proc in self.procs.items():
                if name not in self.reported and proc.poll() is not None:
                    self.reported.add(name)
                    self.say(f"minros learn: {name} (pid {proc.pid}) ended, status "
                             f"{proc.returncode}")

    def too_big(self, limit: int = TRACE_LIMIT) -> str:
        """Why the exercise must stop for the size of its traces ("" while it need not)."""
        size = 0
        for path in self.folder.glob("*.jsonl"):
            try:
                size += path.stat().st_size
            except OSError:
                continue
        if size <= limit:
            return ""
        return (f"its traces in {self.folder} passed {limit >> 20} MB (start it again with the "
                "same command)")

    def stop(self) -> None:
        """Stop every process this runner started (SIGINT, then SIGTERM, then SIGKILL, each
        bounded), newest first."""
        for name in reversed(list(self.procs)):
            _stop(self.procs[name])
        if self.facts:
            self.facts["running"] = False
            try:
                self._save()
            except OSError:
                pass


def _stop(proc: subprocess.Popen) -> None:
    for signame, grace in STOP_GRACE:
        if proc.poll() is not None:
            break
        try:
            os.killpg(proc.pid, getattr(signal, signame))
        except (ProcessLookupError, PermissionError):
            break
        try:
            proc.wait(grace)
        except subprocess.TimeoutExpired:
            continue
    if proc.stdout is not None:
        proc.stdout.close()


def _events(path: Path) -> List[Dict[str, Any]]:
    """The whole lines of a trace file that is being written (a cut last line is left)."""
    try:
        data = path.read_bytes()
    except OSError:
        return []
    out = []
    for line in data.split(b"\n")[:-1]:
        try:
            ev = json.loads(line)
        except ValueError:
            continue
        if isinstance(ev, dict):
            out.append(ev)
    return out


def load_attempt(folder: Path, answer: Iterable[str], extra: Iterable[Path] = ()) -> Attempt:
    """The answer and every trace of ``folder`` (``me`` is every ``me*.jsonl`` and the files
    in ``extra`` together), with the facts of the last start."""
    facts = read_state(folder)
    traces: Dict[str, List[Dict[str, Any]]] = {}
    mine: List[Dict[str, Any]] = []
    for path in sorted(folder.glob("*.jsonl")):
        events = _events(path)
        if path.stem.startswith("me"):
            mine.extend(events)
        traces[path.stem] = events
    for path in extra:
        if not path.is_file():
            raise LearnError(f"no trace file {path}")
        mine.extend(_events(path))
    mine.sort(key=lambda ev: ev.get("t", 0))
    traces["me"] = mine
    return Attempt(" ".join(answer), traces, facts)
