"""roslaunch.pmon: the process monitor of roslaunch's process API.

A :class:`ProcessMonitor` is a thread that watches registered :class:`Process` objects: it
reports deaths (to the console and to its :class:`ProcessListener` s), restarts those that
respawn once their ``respawn_delay`` has passed, shuts the launch down when a required one
dies or when every process is gone after registrations are complete, and on exit stops what
is left (ordinary processes in parallel, core processes last, in reverse order). Tools and
tests that drive roslaunch's parent, child and runner objects use this; minros's own
``roslaunch`` command runs :class:`minros.launch.runner.LaunchRunner`.

Written after roslaunch's behaviour and texts; the stand-in ``roslaunch.pmon`` *is* this
module (callers set ``_shutting_down``).
"""

from __future__ import annotations

import atexit
import logging
import queue
import signal
import sys
import threading
import time
import traceback
from typing import Any, Dict, List, Optional

from minros.launch.rosmodel import RLException, printerrlog, printlog, printlog_bold

logger = logging.getLogger("roslaunch.pmon")


class FatalProcessLaunch(RLException):
    """A process could not be started, and trying again will not help."""


# -- starting and stopping monitors ---------------------------------------------------------

_pmons: List[ProcessMonitor] = []
_pmon_counter = 0
_shutdown_lock = threading.Lock()
_shutting_down = False


def start_process_monitor() -> Optional[ProcessMonitor]:
    """A new running monitor (None once the process is shutting down)."""
    global _pmon_counter
    if _shutting_down:
        return None
    _pmon_counter += 1
    monitor = ProcessMonitor(f"ProcessMonitor-{_pmon_counter}")
    with _shutdown_lock:  # a Ctrl-C during start must see it in _pmons
        _pmons.append(monitor)
        monitor.start()
    return monitor


def shutdown_process_monitor(process_monitor: Any) -> bool:
    """Shut ``process_monitor`` down and wait for it (20 s); True when it ended. Never raises:
    this runs while the program exits."""
    try:
        if process_monitor is None or process_monitor.is_shutdown:
            return False
        process_monitor.shutdown()
        process_monitor.join(20.0)
        if process_monitor.is_alive():
            logger.error("shutdown_process_monitor: ProcessMonitor shutdown failed!")
            return False
        return True
    except Exception as exc:  # noqa: BLE001
        print(f"exception in shutdown_process_monitor: {exc}", file=sys.stderr)
        traceback.print_exc()
        return False


def pmon_shutdown() -> None:
    """Shut every monitor started by :func:`start_process_monitor` down."""
    with _shutdown_lock:
        try:
            for monitor in _pmons:
                shutdown_process_monitor(monitor)
            del _pmons[:]
        except Exception:  # noqa: BLE001
            print("exception in pmon_shutdown")
            traceback.print_exc()


# -- signals: SIGINT/SIGTERM/SIGHUP shut the monitors down, then go to the previous handler ---

_signal_list = [signal.SIGTERM, signal.SIGINT, signal.SIGHUP]
_signal_chain: Dict[int, Any] = {}
_sig_initialized = False


def rl_signal(sig: int, stackframe: Any) -> None:
    global _shutting_down
    if _shutting_down:
        return
    _shutting_down = True
    pmon_shutdown()
    previous = _signal_chain.get(sig)
    if previous not in (None, signal.SIG_IGN, signal.SIG_DFL, rl_signal):
        try:
            previous(sig, stackframe)
        except KeyboardInterrupt:
            pass  # Python's own SIGINT handler: the monitors are down already


def _is_interactive() -> bool:
    return bool(getattr(sys, "ps1", None)) or bool(sys.flags.interactive)


def _init_signal_handlers() -> None:
    """Install the handlers once, from the main thread of a program that is not interactive
    (elsewhere Python refuses, and an interpreter session keeps its own)."""
    global _sig_initialized
    if _sig_initialized:
        return
    if not _is_interactive() and threading.current_thread() is threading.main_thread():
        for sig in _signal_list:
            _signal_chain[sig] = signal.signal(sig, rl_signal)
    atexit.register(pmon_shutdown)
    _sig_initialized = True


# -- processes ------------------------------------------------------------------------------

class Process:
    """A process the monitor watches; subclasses start and stop a real one (this one only
    counts its starts and is dead the moment it is asked)."""

    def __init__(self, package: str, name: str, args: Any, env: Any, respawn: Any = False,
                 respawn_delay: float = 0.0, required: bool = False) -> None:
        self.package = package
        self.name = name
        self.args = args
        self.env = env
        self.respawn = respawn
        self.respawn_delay = respawn_delay
        self.required = required
        self.lock: Any = threading.Lock()
        self.exit_code: Optional[int] = None
        self.spawn_count = 0
        self.time_of_death: Optional[float] = None
        _init_signal_handlers()

    def __str__(self) -> str:
        return f"Process<{self.name}>"

    def get_info(self) -> Dict[str, Any]:
        """Everything about the process (enough to start it again elsewhere)."""
        info = {"spawn_count": self.spawn_count, "args": self.args, "env": self.env,
                "package": self.package, "name": self.name, "alive": self.is_alive(),
                "respawn": self.respawn, "respawn_delay": self.respawn_delay,
                "required": self.required}
        if self.exit_code is not None:
            info["exit_code"] = self.exit_code
        return info

    def start(self) -> Any:
        self.time_of_death = None
        self.spawn_count += 1

    def is_alive(self) -> bool:
        if self.time_of_death is None:
            self.time_of_death = time.time()
        return False

    def should_respawn(self) -> Any:
        """False when the process does not respawn, else the seconds until it may (<= 0: now)."""
        if not self.respawn:
            return False
        if self.time_of_death is None and self.is_alive():
            return False
        return (self.time_of_death or time.time()) + self.respawn_delay - time.time()

    def stop(self, errors: Optional[List[str]] = None) -> None:
        """Stop the process; significant problems go into ``errors``."""

    def get_exit_description(self) -> str:
        if self.exit_code is None:
            return "process has died"
        if self.exit_code:
            return f"process has died [exit code {self.exit_code}]"
        return "process has finished cleanly"


class DeadProcess(Process):
    """What is kept of a process that died: its description, frozen."""

    def __init__(self, p: Process) -> None:
        super().__init__(p.package, p.name, p.args, p.env, p.respawn, p.respawn_delay)
        self.exit_code = p.exit_code
        self.lock = None
        self.spawn_count = p.spawn_count
        self.info = p.get_info()

    def get_info(self) -> Dict[str, Any]:
        return self.info

    def start(self) -> Any:
        raise Exception("cannot call start on a dead process!")

    def is_alive(self) -> bool:
        return False


class ProcessListener:
    """Told when a process dies while monitored (not when shutdown kills it)."""

    def process_died(self, process_name: str, exit_code: Optional[int]) -> None:
        """``exit_code`` None: the monitor could not learn it."""


def _kill_process(p: Process, errors: List[str]) -> None:
    try:
        printlog(f"[{p.name}] killing on exit")
        p.stop(errors)
    except Exception:  # noqa: BLE001 - stopping the others matters more
        traceback.print_exc()
        logger.error(traceback.format_exc())


class _ProcessKiller(threading.Thread):
    """Stops processes from a queue (shutdown runs ten of them)."""

    def __init__(self, q: queue.Queue[Process], i: int) -> None:
        super().__init__(name=f"ProcessKiller-{i}", daemon=True)
        self.q = q
        self.errors: List[str] = []

    def run(self) -> None:
        while True:
            try:
                p = self.q.get(False)
            except queue.Empty:
                return
            try:
                _kill_process(p, self.errors)
            finally:
                self.q.task_done()


class ProcessMonitor(threading.Thread):
    """Watches processes from a thread of its own (see the module's text)."""

    def __init__(self, name: str = "ProcessMonitor") -> None:
        super().__init__(name=name, daemon=True)
        self.procs: List[Process] = []
        self.plock = threading.RLock()
        self.is_shutdown = False
        self.done = False
        self.reacquire_signals: set = set()
        self.listeners: List[Any] = []
        self.dead_list: List[DeadProcess] = []
        self.core_procs: List[Process] = []  # stopped last, newest first
        #: until set, the monitor does not end because it has nothing to watch yet
        self._registrations_complete = False

    # registrations
    def add_process_listener(self, listener: Any) -> None:
        """Add a listener (before the monitor runs)."""
        self.listeners.append(listener)

    def register(self, p: Process) -> None:
        with self.plock:
            if self.has_process(p.name):
                error = f"cannot add process with duplicate name '{p.name}'"
            elif self.is_shutdown:
                error = f"cannot add process [{p.name}] after process monitor has been shut down"
            else:
                self.procs.append(p)
                return
        logger.error("ProcessMonitor.register[%s] failed %s", p.name, error)
        raise RLException(error)

    def register_core_proc(self, p: Process) -> None:
        self.register(p)
        self.core_procs.append(p)

    def registrations_complete(self) -> None:
        """From now on the monitor ends when no process is left."""
        self._registrations_complete = True

    def unregister(self, p: Process) -> None:
        with self.plock:
            self.procs.remove(p)

    def has_process(self, name: str) -> bool:
        return any(p.name == name for p in self.procs)

    def get_process(self, name: str) -> Optional[Process]:
        with self.plock:
            return next((p for p in self.procs if p.name == name), None)

    def get_active_names(self) -> List[str]:
        with self.plock:
            return [p.name for p in self.procs]

    def get_process_names_with_spawn_count(self) -> List[List[Any]]:
        """``[[(name, spawn count) of the live], [the same of the dead]]``."""
        with self.plock:
            return [[(p.name, p.spawn_count) for p in self.procs],
                    [(p.name, p.spawn_count) for p in self.dead_list]]

    def kill_process(self, name: str) -> bool:
        """Stop the process named ``name``; True when there is one. It stays listed until
        the monitor sees it dead."""
        if not isinstance(name, str):
            raise RLException(f"kill_process takes in a process name but was given: {name}")
        printlog(f"[{name}] kill requested")
        with self.plock:
            p = self.get_process(name)
            if p is None:
                return False
            try:
                p.stop([])
            except Exception:  # noqa: BLE001
                logger.error(traceback.format_exc())
            return True

    def shutdown(self) -> None:
        self.is_shutdown = True

    # the main thread's part: signal handlers can only be installed there
    def has_main_thread_jobs(self) -> bool:
        return bool(self.reacquire_signals)

    def do_main_thread_jobs(self) -> None:
        for sig in list(self.reacquire_signals):
            _signal_chain[sig] = signal.signal(sig, rl_signal)
            self.reacquire_signals.discard(sig)

    def mainthread_spin_once(self) -> bool:
        """One round of main-thread work; False once the monitor is done."""
        if self.done:
            return False
        if self.has_main_thread_jobs():
            self.do_main_thread_jobs()
        return True

    def mainthread_spin(self) -> None:
        """Main-thread work until the monitor is done."""
        while not self.done:
            time.sleep(0.1)
            if self.has_main_thread_jobs():
                self.do_main_thread_jobs()

    # the thread
    def run(self) -> None:
        try:
            try:
                self._run()
            except Exception:  # noqa: BLE001 - an exception must not skip the cleanup
                logger.error(traceback.format_exc())
                traceback.print_exc()
        finally:
            self._post_run()

    def _report_death(self, p: Process, respawning: List[Process], dead: List[Process]) -> None:
        description = p.get_exit_description()
        if p.required:
            printerrlog("=" * 80 + f"REQUIRED process [{p.name}] has died!\n{description}\n"
                        "Initiating shutdown!\n" + "=" * 80)
            self.is_shutdown = True
        elif p not in respawning:
            (printerrlog if p.exit_code else printlog_bold)(f"[{p.name}] {description}")
            dead.append(p)
        for listener in self.listeners:
            listener.process_died(p.name, p.exit_code)

    def _run(self) -> None:
        dead: List[Process] = []
        respawning: List[Process] = []
        while not self.is_shutdown:
            with self.plock:
                procs = self.procs[:]
            if self.is_shutdown:
                break
            # a child may have taken a signal over: the main thread takes it back
            if _sig_initialized and _signal_chain:
                for sig in _signal_list:
                    if signal.getsignal(sig) is not rl_signal:
                        self.reacquire_signals.add(sig)
            for p in procs:
                try:
                    if not p.is_alive():
                        self._report_death(p, respawning, dead)
                except Exception:  # noqa: BLE001 - a broken process is dead, not respawned
                    traceback.print_exc()
                    dead.append(p)
                if self.is_shutdown:
                    break
            for d in dead:
                try:
                    if d.should_respawn() is not False:  # 0.0 means now
                        respawning.append(d)
                    else:
                        self.unregister(d)
                        d.stop([])
                        with self.plock:
                            self.dead_list.append(DeadProcess(d))
                except Exception:  # noqa: BLE001
                    logger.error(traceback.format_exc())
            # only after at least one death: a monitor waits for its first process
            if self._registrations_complete and dead and not self.procs and not respawning:
                printlog("all processes on machine have died, roslaunch will exit")
                self.is_shutdown = True
            del dead[:]
            waiting = []
            for r in respawning:
                if self.is_shutdown:
                    break
                try:
                    if r.should_respawn() <= 0.0:
                        printlog(f"[{r.name}] restarting process")
                        r.stop([])
                        r.start()
                    else:
                        waiting.append(r)
                except Exception:  # noqa: BLE001
                    traceback.print_exc()
                    logger.error("Restart failed %s", traceback.format_exc())
            respawning = waiting
            time.sleep(0.1)

    def _post_run(self) -> None:
        """Stop what is left: ordinary processes in parallel, then core ones in reverse."""
        self.is_shutdown = True
        q: queue.Queue[Process] = queue.Queue()
        with self.plock:
            core_procs = self.core_procs[:]
            for p in reversed(self.procs):
                if p not in core_procs:
                    q.put(p)
        killers = [_ProcessKiller(q, i) for i in range(10)]
        for killer in killers:
            killer.start()
        q.join()
        errors: List[str] = []
        for killer in killers:
            errors.extend(killer.errors)
        for p in reversed(core_procs):  # the master goes last
            _kill_process(p, errors)
        with self.plock:
            del self.procs[:]
            del self.core_procs[:]
        self.reacquire_signals.clear()
        self.done = True
        if errors:
            printerrlog("Shutdown errors:\n" + "\n".join(f" * {e}" for e in errors))


__all__ = ["DeadProcess", "FatalProcessLaunch", "Process", "ProcessListener", "ProcessMonitor",
           "pmon_shutdown", "rl_signal", "shutdown_process_monitor", "start_process_monitor"]
