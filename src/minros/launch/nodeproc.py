"""roslaunch.nodeprocess: local processes for roslaunch's process monitor.

:class:`LocalProcess` is a :class:`minros.launch.procmon.Process` that runs a program on this
machine through minros's :class:`minros.launch.runner.LaunchProcess` (its own session, stdin
inherited, console output to ``<log dir>/<run id>/<name>-stdout.log`` and ``-stderr.log``
unless it goes to the screen, SIGINT then SIGTERM then SIGKILL to its process group on stop);
what this module adds is roslaunch's bookkeeping: spawn counts, ``__log:=`` for nodes, the
start and exit texts, the SIGINT and SIGTERM timeouts.
"""

from __future__ import annotations

import os
import sys
import threading
import time
from pathlib import Path
from typing import Any, Dict, List, Optional

from minros import names, rosenv
from minros.launch.procmon import FatalProcessLaunch, Process
from minros.launch.rosmodel import (  # noqa: F401 - roslaunch.nodeprocess has them too
    PHASE_RUN,
    PHASE_SETUP,
    PHASE_TEARDOWN,
    TEST_TIME_LIMIT_DEFAULT,
    Master,
    RLException,
    printerrlog,
    printlog_bold,
    setup_env,
)
from minros.launch.runner import LaunchProcess

DEFAULT_TIMEOUT_SIGINT = 15.0  # seconds
DEFAULT_TIMEOUT_SIGTERM = 2.0  # seconds
NUM_WORKERS = 3  # rosmaster's threads calling nodes back

_counter = 0
_counter_lock = threading.Lock()


def _next_counter() -> int:
    global _counter
    with _counter_lock:
        _counter += 1
        return _counter


def _cleanup_remappings(args: List[str], prefix: str) -> List[str]:
    """``args`` without those that start with ``prefix`` (a respawn adds ``__log:=`` again)."""
    for arg in [a for a in args if a.startswith(prefix)]:
        args.remove(arg)
    return args


def _check_timeouts(sigint_timeout: float, sigterm_timeout: float) -> None:
    if sigint_timeout <= 0:
        raise RLException(f"sigint_timeout must be a positive number, received {sigint_timeout:f}")
    if sigterm_timeout <= 0:
        raise RLException(f"sigterm_timeout must be a positive number, received {sigterm_timeout:f}")


def create_master_process(run_id: str, type_: str, ros_root: Any, port: int,
                          num_workers: int = NUM_WORKERS, timeout: Optional[float] = None,
                          master_logger_level: Any = False,
                          sigint_timeout: float = DEFAULT_TIMEOUT_SIGINT,
                          sigterm_timeout: float = DEFAULT_TIMEOUT_SIGTERM) -> LocalProcess:
    """The master as a (required, not yet started) process: ``rosmaster --core -p PORT``."""
    if port < 1 or port > 65535:
        raise RLException(f"invalid port assignment: {port}")
    if type_ not in (Master.ROSMASTER, Master.ZENMASTER):
        raise RLException(f"unknown master typ_: {type_}")
    args = [type_, "--core", "-p", str(port), "-w", str(num_workers)]
    if timeout is not None:
        args += ["-t", str(timeout)]
    if master_logger_level:
        args += ["--master-logger-level", str(master_logger_level)]
    return LocalProcess(run_id, "rosmaster", "master", args, os.environ, False, None,
                        required=True, sigint_timeout=sigint_timeout,
                        sigterm_timeout=sigterm_timeout)


def create_node_process(run_id: str, node: Any, master_uri: str,
                        sigint_timeout: float = DEFAULT_TIMEOUT_SIGINT,
                        sigterm_timeout: float = DEFAULT_TIMEOUT_SIGTERM) -> LocalProcess:
    """A (not yet started) process for ``node``, whose name and machine are assigned.
    NodeParamsException when its program cannot be found."""
    from minros.launch.rostools import create_local_process_args

    machine = node.machine
    if machine is None:
        raise RLException(f"Internal error: no machine selected for node of type "
                          f"[{node.package}/{node.type}]")
    if not node.name:
        raise ValueError("node name must be assigned")
    env = setup_env(node, machine, master_uri)
    name = f"{names.ns_join(node.namespace, node.name)}-{_next_counter()}".lstrip("/")
    args = create_local_process_args(node, machine)
    return LocalProcess(run_id, node.package, name, args, env, node.output != "screen",
                        respawn=node.respawn, respawn_delay=node.respawn_delay,
                        required=node.required, cwd=node.cwd, sigint_timeout=sigint_timeout,
                        sigterm_timeout=sigterm_timeout)


class LocalProcess(Process):
    """A program run on this machine (see the module's text)."""

    def __init__(self, run_id: Optional[str], package: str, name: str, args: List[str],
                 env: Any, log_output: bool, respawn: bool = False, respawn_delay: float = 0.0,
                 required: bool = False, cwd: Optional[str] = None, is_node: bool = True,
                 sigint_timeout: float = DEFAULT_TIMEOUT_SIGINT,
                 sigterm_timeout: float = DEFAULT_TIMEOUT_SIGTERM) -> None:
        super().__init__(package, name, args, env, respawn, respawn_delay, required)
        _check_timeouts(sigint_timeout, sigterm_timeout)
        self.run_id = run_id
        self.popen: Any = None
        self.log_output = log_output
        self.started = False
        self.stopped = False
        self.cwd = cwd
        self.log_dir: Optional[str] = None
        self.pid = -1
        self.is_node = is_node
        self.sigint_timeout = sigint_timeout
        self.sigterm_timeout = sigterm_timeout
        self._process: Optional[LaunchProcess] = None

    def get_info(self) -> Dict[str, Any]:
        info = super().get_info()
        info["pid"] = self.pid
        if self.run_id:
            info["run_id"] = self.run_id
        info["log_output"] = self.log_output
        if self.cwd is not None:
            info["cwd"] = self.cwd
        return info

    def _log_name(self) -> str:
        return self.name.replace("/", "-")

    def _configure_logging(self) -> Path:
        """The log folder (``<ROS_LOG_DIR>/<run id>``), made; a node is told its log file."""
        log_dir = rosenv.ros_log_dir()
        if self.run_id:
            log_dir = log_dir / self.run_id
        try:
            log_dir.mkdir(parents=True, exist_ok=True)
        except OSError as exc:
            raise RLException(f"unable to create directory for log file [{log_dir}]: "
                              f"{exc.strerror}") from None
        self.log_dir = str(log_dir)
        if self.is_node:
            self.args = _cleanup_remappings(self.args, "__log:=")
            self.args.append(f"__log:={log_dir / self._log_name()}.log")
        return log_dir

    def _working_dir(self) -> str:
        if self.cwd == "node":
            return os.path.dirname(self.args[0])
        if self.cwd == "cwd":
            return os.getcwd()
        if self.cwd == "ros-root":
            return os.environ.get("ROS_ROOT") or str(rosenv.ros_home())
        return str(rosenv.ros_home())

    def start(self) -> bool:
        """Start (or restart) the program; False when it exits at once with a failure.
        FatalProcessLaunch when it cannot be run at all."""
        from minros.workspace.executables import child_environment

        super().start()
        with self.lock:
            self.started = self.stopped = False
            try:
                log_dir: Optional[Path] = self._configure_logging()
            except Exception as exc:  # noqa: BLE001 - run it anyway, output to the console
                printerrlog(f"[{self.name}] ERROR: unable to configure logging [{exc}]")
                log_dir = None
            cwd = self._working_dir()
            os.makedirs(cwd, exist_ok=True)
            if self._process is None:
                self._process = LaunchProcess(self.name, [], {}, cwd, log_dir=log_dir,
                                              screen=not self.log_output)
            process = self._process
            # minros's interpreter folder on PATH: `rosmaster` and scripts' `python` are its
            process.argv = [str(a) for a in self.args]
            process.env = child_environment(dict(self.env))
            process.cwd, process.log_dir = cwd, log_dir
            try:
                self.pid = process.start()
            except OSError as exc:
                self.started = True
                if exc.errno == 8:  # ENOEXEC
                    raise FatalProcessLaunch(f"Unable to launch [{self.name}]. \nIf it is a script, "
                                             "you may be missing a '#!' declaration at the top.") from None
                if exc.errno == 2:  # ENOENT
                    raise FatalProcessLaunch(
                        f"Roslaunch got a '{exc.strerror}' error while attempting to run:\n\n"
                        f"{' '.join(process.argv)}\n\nPlease make sure that all the executables in "
                        "this command exist and have\nexecutable permission. This is often caused "
                        "by a bad launch-prefix.") from None
                raise FatalProcessLaunch(f"unable to launch [{' '.join(process.argv)}]: "
                                         f"{exc.strerror}") from None
            self.popen = process.popen
            self.started = True
            code = self.popen.poll()
            if code is None or code == 0:
                printlog_bold(f"process[{self.name}]: started with pid [{self.pid}]")
                return True
            printerrlog(f"failed to start local process: {' '.join(process.argv)}")
            return False

    def is_alive(self) -> bool:
        if not self.started:  # not started yet: not dead either
            return True
        if self.stopped or self.popen is None:
            if self.time_of_death is None:
                self.time_of_death = time.time()
            return False
        self.exit_code = self.popen.poll()
        if self.exit_code is not None:
            if self.time_of_death is None:
                self.time_of_death = time.time()
            return False
        return True

    def get_exit_description(self) -> str:
        command = " ".join(str(a) for a in self.args)
        if self.exit_code is None:
            text = f"process has died without exit code [pid {self.pid}, cmd {command}]."
        elif self.exit_code != 0:
            text = f"process has died [pid {self.pid}, exit code {self.exit_code}, cmd {command}]."
        else:
            text = "process has finished cleanly"
        if self.log_dir:
            text += f"\nlog file: {os.path.join(self.log_dir, self._log_name())}*.log"
        return text

    def stop(self, errors: Optional[List[str]] = None) -> None:
        """SIGINT its process group, SIGTERM after ``sigint_timeout``, SIGKILL after
        ``sigterm_timeout`` more (which goes into ``errors``)."""
        errors = [] if errors is None else errors
        super().stop(errors)
        with self.lock:
            try:
                if self.popen is None or self._process is None:
                    return
                self.exit_code = self.popen.poll()
                if self.exit_code is not None:
                    return
                pid = self.popen.pid

                def report(text: str) -> None:
                    printerrlog(text)
                    if "SIGKILL" in text:
                        errors.append(f"process[{self.name}, pid {pid}]: required SIGKILL. "
                                      "May still be running.")

                self._process.stop(self.sigint_timeout, self.sigterm_timeout, report)
                self.exit_code = self._process.exit_code
            except Exception as exc:  # noqa: BLE001 - shutdown goes on with the others
                print(f"[{self.name}] EXCEPTION {exc}", file=sys.stderr)
            finally:
                self.popen = None
                self.stopped = True


__all__ = ["DEFAULT_TIMEOUT_SIGINT", "DEFAULT_TIMEOUT_SIGTERM", "LocalProcess", "NUM_WORKERS",
           "create_master_process", "create_node_process"]
