"""Running a loaded launch: master, parameters, node processes and their monitor.

Order and console messages follow roslaunch: summary, warnings, the master (started here if
none answers at ROS_MASTER_URI), ``/run_id``, cleared and set parameters, then the nodes in
file order, each in its own process group. The monitor restarts ``respawn`` nodes after
``respawn_delay``, stops everything when a ``required`` node exits, and on Ctrl-C (SIGINT),
SIGTERM or SIGHUP stops the nodes in reverse order (SIGINT, then SIGTERM, then SIGKILL, each
bounded) and the master it started last. It also rotates the console logs of ``output="log"``
processes (``<node>-stdout.log``), which ROS lets grow, as a node's own log is rotated.
"""

from __future__ import annotations

import os
import shlex
import signal
import socket
import subprocess
import sys
import threading
import time
import uuid
from pathlib import Path
from typing import Any, Callable, Dict, List, TextIO, Tuple
from urllib.parse import urlparse

from minros import logfiles, names
from minros.launch.config import LaunchConfig, LaunchError, NodeSpec
from minros.rosenv import renew_latest_log_dir, ros_home, ros_log_dir
from minros.signals import SignalWatch

Print = Callable[[str], None]

#: Bounds for stopping a process (roslaunch's --sigint-timeout / --sigterm-timeout defaults).
SIGINT_TIMEOUT = 15.0
SIGTERM_TIMEOUT = 2.0
MASTER_START_TIMEOUT = 20.0
POLL_INTERVAL = 0.05
#: how often the console logs of ``output="log"`` processes are checked for rotation
LOG_ROTATION_INTERVAL = 1.0


def master_is_up(uri: str, timeout: float = 1.0) -> bool:
    from minros.tools.master import Master

    master = Master("/roslaunch", uri, timeout)
    try:
        master.get_pid()  # raises unless the master answers SUCCESS
        return True
    except Exception:
        return False
    finally:
        master.close()


def is_local_host(host: str) -> bool:
    if host in ("localhost", "127.0.0.1", "::1", "") or host.startswith("127."):
        return True
    try:
        local = {socket.gethostname(), socket.getfqdn()}
        if host in local:
            return True
        addresses = {info[4][0] for info in socket.getaddrinfo(host, None)}
        local_addresses = {info[4][0] for name in local for info in socket.getaddrinfo(name, None)}
        return bool(addresses & (local_addresses | {"127.0.0.1", "::1"}))
    except OSError:
        return False


log_root = ros_log_dir  # roslaunch's name for it


def _die_with_parent() -> None:
    """In the child before exec (Linux): SIGTERM when roslaunch dies, even by SIGKILL, so a
    killed roslaunch leaves no node behind. roslaunch starts processes from its main thread
    only, which lives as long as the process (the signal follows the forking thread)."""
    try:
        import ctypes

        libc = ctypes.CDLL(None, use_errno=True)
        pr_set_pdeathsig = 1
        libc.prctl(pr_set_pdeathsig, signal.SIGTERM, 0, 0, 0)
    except Exception:  # not Linux or no libc: roslaunch's own shutdown still stops the nodes
        pass


_PREEXEC = _die_with_parent if sys.platform.startswith("linux") else None


def _safe_printer(stream: TextIO) -> Print:
    """A printer that never raises: a closed terminal or pipe (``roslaunch x | head``) must not
    stop roslaunch from cleaning up its processes."""

    def emit(line: str) -> None:
        try:
            # one write() per line: nodes with output="screen" share the terminal, and under
            # PYTHONUNBUFFERED print() writes a line and its newline in two system calls, between
            # which a node's own line could land ("...pid [42]PROBE ...")
            stream.write(line + "\n")
            stream.flush()
        except (OSError, ValueError):
            pass

    return emit


class LaunchProcess:
    """One node process (or the master): how to start it, and its live state."""

    def __init__(self, name: str, argv: List[str], env: Dict[str, str], cwd: str,
                 spec: NodeSpec | None = None, log_dir: Path | None = None,
                 screen: bool = True, log_stem: str | None = None) -> None:
        self.name = name
        self.log_stem = log_stem
        self.argv = argv
        self.env = env
        self.cwd = cwd
        self.spec = spec
        self.log_dir = log_dir
        self.screen = screen
        self.popen: subprocess.Popen | None = None
        self.exit_code: int | None = None
        self.died_at: float | None = None
        self.started_once = False
        self._files: List[TextIO] = []

    @property
    def respawn(self) -> bool:
        return bool(self.spec and self.spec.respawn)

    @property
    def required(self) -> bool:
        return bool(self.spec and self.spec.required)

    def log_name(self) -> str:
        return self.log_stem or self.name.replace("/", "-")

    def start(self) -> int:
        stdout: Any = None
        stderr: Any = None
        self._close_files()
        if not self.screen and self.log_dir is not None:
            self.log_dir.mkdir(parents=True, exist_ok=True)
            # appending (O_APPEND), so that rotate_logs() can empty a file the node writes
            out = open(self.log_dir / f"{self.log_name()}-stdout.log", "a")  # noqa: SIM115
            err = open(self.log_dir / f"{self.log_name()}-stderr.log", "a")  # noqa: SIM115
            if not self.started_once:
                out.truncate(0)
                err.truncate(0)
            self._files = [out, err]
            stdout, stderr = out, err
        # stdin inherited, as ROS's roslaunch does: a keyboard teleop started from a launch file
        # reads the terminal (in a session of its own, it gets no job-control signals from it)
        self.popen = subprocess.Popen(self.argv, env=self.env, cwd=self.cwd, stdin=None,
                                      stdout=stdout, stderr=stderr, start_new_session=True,
                                      preexec_fn=_PREEXEC)
        self.exit_code = None
        self.died_at = None
        self.started_once = True
        return self.popen.pid

    def poll(self) -> bool:
        """Whether the process is alive; records exit code and time of death otherwise."""
        if self.popen is None:
            return False
        code = self.popen.poll()
        if code is None:
            return True
        if self.died_at is None:
            self.exit_code = code
            self.died_at = time.monotonic()
        return False

    def exit_description(self) -> str:
        pid = self.popen.pid if self.popen else None
        if self.exit_code is None:
            text = f"process has died without exit code [pid {pid}, cmd {' '.join(self.argv)}]."
        elif self.exit_code != 0:
            text = f"process has died [pid {pid}, exit code {self.exit_code}, cmd {' '.join(self.argv)}]."
        else:
            text = "process has finished cleanly"
        if self.log_dir is not None:
            text += f"\nlog file: {self.log_dir / self.log_name()}*.log"
        return text

    def stop(self, sigint_timeout: float, sigterm_timeout: float, err: Print) -> None:
        """SIGINT the process group, then SIGTERM, then SIGKILL, each bounded."""
        if self.popen is None:
            return
        pgid = self.popen.pid
        steps = ((signal.SIGINT, sigint_timeout, None), (signal.SIGTERM, sigterm_timeout, "SIGTERM"),
                 (signal.SIGKILL, 5.0, "SIGKILL"))
        for sig, timeout, label in steps:
            if self.popen.poll() is not None:
                break
            if label:
                err(f"[{self.name}] escalating to {label}")
            try:
                os.killpg(pgid, sig)
            except ProcessLookupError:
                break
            except PermissionError:
                self.popen.send_signal(sig)
            try:
                self.popen.wait(timeout)
            except subprocess.TimeoutExpired:
                continue
        try:  # helpers a node started in its group must not outlive it
            os.killpg(pgid, signal.SIGKILL)
        except (ProcessLookupError, PermissionError):
            pass
        self.poll()
        self._close_files()

    def rotate_logs(self) -> None:
        """Keep the console logs of an ``output="log"`` process within a node log's bounds
        (ROS lets them grow; here they rotate at 50 MB keeping 4, as the node's own log)."""
        for f in self._files:
            try:
                logfiles.rotate_copy_truncate(f.name, logfiles.NODE_LOG_MAX_BYTES,
                                              logfiles.NODE_LOG_BACKUPS)
            except OSError:
                pass  # a full disk must not stop the monitor

    def _close_files(self) -> None:
        for f in self._files:
            try:
                f.close()
            except OSError:
                pass
        self._files = []


class LaunchRunner:
    """Runs a :class:`LaunchConfig` until Ctrl-C, a required node's exit or all nodes exit."""

    def __init__(self, config: LaunchConfig, *, master_uri: str, env: Dict[str, str] | None = None,
                 port: int | None = None, screen: bool = False, wait_for_master: bool = False,
                 run_id: str | None = None, core_only: bool = False, core_nodes: bool = True,
                 sigint_timeout: float = SIGINT_TIMEOUT, sigterm_timeout: float = SIGTERM_TIMEOUT,
                 out: Print | None = None, err: Print | None = None) -> None:
        self.config = config
        self.env = dict(os.environ if env is None else env)
        self.master_uri = master_uri
        self.port = port
        self.screen = screen
        self.wait_for_master = wait_for_master
        self.run_id = run_id
        self.core_only = core_only
        #: whether a master started here comes with roscore's nodes (rosout), as roslaunch's
        #: does; rostest's master has none
        self.core_nodes = core_nodes
        self.sigint_timeout = sigint_timeout
        self.sigterm_timeout = sigterm_timeout
        self.out: Print = out or _safe_printer(sys.stdout)
        self.err: Print = err or _safe_printer(sys.stderr)
        self.master: LaunchProcess | None = None
        self.processes: List[LaunchProcess] = []
        self.shutdown = threading.Event()
        self._counter = 0
        self.log_dir: Path | None = None
        self.exit_code = 0

    # -- setup
    def _next_name(self, resolved: str) -> str:
        self._counter += 1
        return f"{resolved.lstrip('/')}-{self._counter}"

    def _master(self) -> Any:
        from minros.tools.master import Master

        return Master("/roslaunch", self.master_uri)

    def _start_master(self) -> None:
        if master_is_up(self.master_uri):
            return
        parsed = urlparse(self.master_uri)
        host, port = parsed.hostname or "localhost", parsed.port or 11311
        if self.wait_for_master:
            self.out(f"waiting for master at [{self.master_uri}]")
            while not self.shutdown.is_set() and not master_is_up(self.master_uri):
                self.shutdown.wait(0.5)
            return
        if not is_local_host(host):
            raise LaunchError(f"unable to contact ROS master at [{self.master_uri}] "
                              "(it is not on this machine, so roslaunch cannot start it)")
        self.out("auto-starting new master")
        argv = [sys.executable, "-m", "minros", "core", "-p", str(port)]
        if not self.core_nodes:
            argv.append("--no-rosout")
        env = dict(self.env, ROS_MASTER_URI=self.master_uri)
        # the master's own console output goes to a log file, as roslaunch does with rosmaster's
        self.master = LaunchProcess("master", argv, env, str(ros_home(self.env)), screen=False,
                                    log_dir=log_root(self.env), log_stem=f"master-{port}")
        ros_home(self.env).mkdir(parents=True, exist_ok=True)
        pid = self.master.start()
        self.out(f"process[master]: started with pid [{pid}]")
        deadline = time.monotonic() + MASTER_START_TIMEOUT
        while not master_is_up(self.master_uri):
            if not self.master.poll():
                raise LaunchError(f"the master exited at start ({self.master.exit_description()})")
            if time.monotonic() > deadline or self.shutdown.is_set():
                raise LaunchError(f"the master did not answer at [{self.master_uri}] "
                                  f"within {MASTER_START_TIMEOUT:.0f} s")
            time.sleep(0.05)

    def _setup_run_id(self) -> None:
        from minros.tools.master import MasterError

        master = self._master()
        try:
            value = master.get_param("/run_id")
        except MasterError:  # not set
            self.run_id = self.run_id or str(uuid.uuid1())
            self.out(f"setting /run_id to {self.run_id}")
            master.set_param("/run_id", self.run_id)
        else:
            if self.run_id and value != self.run_id:
                raise LaunchError(f"run_id on parameter server does not match declared run_id: "
                                  f"{value} vs {self.run_id}")
            self.run_id = value
        self.log_dir = log_root(self.env) / self.run_id
        try:
            self.log_dir.mkdir(parents=True, exist_ok=True)
        except OSError:
            return  # the nodes report it when they open their log files
        renew_latest_log_dir(self.log_dir)

    def _load_parameters(self) -> None:
        from minros.tools.master import MasterException

        master = self._master()
        for ns in self.config.clear_params:
            try:
                if master.has_param(ns):
                    master.delete_param(ns)
            except MasterException:
                pass
        for command in self.config.rosparam_commands:
            self._rosparam_command(master, command)
        last = None
        try:
            for key, value in self.config.params.items():
                last = key
                try:
                    master.set_param(key, value)
                except MasterException as exc:
                    raise LaunchError(f"unable to set parameter [{key}]: {exc}") from None
        except LaunchError:
            raise
        except Exception as exc:
            raise LaunchError(f"load_parameters: unable to set parameters (last param was [{last}]): {exc}") from None

    def _rosparam_command(self, master: Any, command: Tuple[str, ...]) -> None:
        from minros.tools.master import MasterException

        if command[0] == "delete":
            try:
                master.delete_param(command[1])
            except MasterException:
                self.err(f"WARNING: rosparam delete: parameter [{command[1]}] is not set")
            return
        _dump, path, key = command
        try:
            data = master.get_param(key)
        except MasterException:
            data = {}
        import yaml

        try:
            Path(path).write_text(yaml.safe_dump(data, default_flow_style=False))
        except OSError as exc:
            self.err(f"WARNING: rosparam dump to [{path}] failed: {exc.strerror}")

    def node_command(self, spec: NodeSpec, proc_name: str) -> Tuple[List[str], str]:
        """argv and working directory of a node, as roslaunch builds them."""
        from minros.workspace.executables import ExecutableError, resolve_executable

        try:
            command = resolve_executable(spec.package, spec.type)
        except ExecutableError as exc:
            if exc.exit_code == 2:
                raise LaunchError(f"cannot launch node of type [{spec.package}/{spec.type}]: "
                                  f"{spec.package}", spec.filename, spec.line) from None
            raise LaunchError(
                f"cannot launch node of type [{spec.package}/{spec.type}]: Cannot locate node of type "
                f"[{spec.type}] in package [{spec.package}]. Make sure file exists in package path "
                "and permission is set to executable (chmod +x)",
                spec.filename, spec.line) from None
        try:
            prefix = shlex.split(spec.launch_prefix) if spec.launch_prefix else []
            args = shlex.split(spec.args) if spec.args else []
        except ValueError as exc:
            raise LaunchError(f"node [{spec.resolved_name}]: cannot split args: {exc}",
                              spec.filename, spec.line) from None
        argv = prefix + command + args + [f"{src}:={dst}" for src, dst in spec.remap_args]
        argv.append(f"__name:={spec.name}")
        if self.log_dir is not None:
            argv.append(f"__log:={self.log_dir / proc_name.replace('/', '-')}.log")
        cwd = str(ros_home(self.env))
        if spec.cwd == "node":
            exe = Path(command[-1])
            cwd = str(exe.parent) if exe.is_file() else cwd
        return argv, cwd

    def node_env(self, spec: NodeSpec) -> Dict[str, str]:
        from minros.workspace.executables import child_environment

        env = child_environment(self.env)
        env["ROS_MASTER_URI"] = self.master_uri
        if spec.namespace and spec.namespace != "/":
            env["ROS_NAMESPACE"] = spec.namespace.rstrip("/")  # roslaunch passes "/g", not "/g/"
        else:
            env.pop("ROS_NAMESPACE", None)
        for key, value in spec.env_args:
            env[key] = value
        return env

    def _start_nodes(self) -> None:
        for spec in self.config.nodes:
            if self.shutdown.is_set():
                return
            if spec.machine:
                machine = self.config.machines[spec.machine]
                if not is_local_host(machine.address):
                    self.err(f"ERROR: cannot launch node [{spec.resolved_name}] on machine "
                             f"[{machine.name}]: minros runs nodes on this machine only")
                    continue
            proc_name = self._next_name(names.ns_join(spec.namespace, spec.name))
            try:
                argv, cwd = self.node_command(spec, proc_name)
            except LaunchError as exc:
                self.err(f"ERROR: {exc.message}")
                continue
            screen = self.screen or spec.output == "screen"
            proc = LaunchProcess(proc_name, argv, self.node_env(spec), cwd, spec=spec,
                                 log_dir=self.log_dir, screen=screen)
            Path(cwd).mkdir(parents=True, exist_ok=True)
            try:
                pid = proc.start()
            except OSError as exc:
                self.err(f"failed to start local process: {' '.join(argv)} ({exc.strerror})")
                self.err(f"local launch of {spec.package}/{spec.type} failed")
                continue
            self.processes.append(proc)
            self.out(f"process[{proc_name}]: started with pid [{pid}]")

    # -- monitor
    def _monitor(self) -> None:
        waiting_respawn: Dict[str, LaunchProcess] = {}
        next_rotation = time.monotonic() + LOG_ROTATION_INTERVAL
        while not self.shutdown.is_set():
            if time.monotonic() >= next_rotation:
                next_rotation = time.monotonic() + LOG_ROTATION_INTERVAL
                for proc in [*self.processes, *([self.master] if self.master else [])]:
                    proc.rotate_logs()
            for proc in list(self.processes):
                if proc.poll() or proc.name in waiting_respawn:
                    continue
                description = proc.exit_description()
                if proc.required:
                    self.err("=" * 80 + f"REQUIRED process [{proc.name}] has died!\n{description}\n"
                             "Initiating shutdown!\n" + "=" * 80)
                    self.shutdown.set()
                    break
                if proc.respawn:
                    waiting_respawn[proc.name] = proc
                    if proc.exit_code:
                        self.err(f"[{proc.name}] {description}")
                    else:
                        self.out(f"[{proc.name}] {description}")
                    continue
                if proc.exit_code:
                    self.err(f"[{proc.name}] {description}")
                else:
                    self.out(f"[{proc.name}] {description}")
                proc.stop(0, 0, self.err)
                self.processes.remove(proc)
                if not self.processes and not waiting_respawn and self.master is None:
                    self.out("all processes on machine have died, roslaunch will exit")
                    self.shutdown.set()
            for name, proc in list(waiting_respawn.items()):
                if self.shutdown.is_set():
                    break
                delay = proc.spec.respawn_delay if proc.spec else 0.0
                if time.monotonic() - (proc.died_at or 0.0) >= delay:
                    self.out(f"[{name}] restarting process")
                    proc.stop(0, 0, self.err)
                    try:
                        pid = proc.start()
                    except OSError as exc:
                        self.err(f"[{name}] restart failed: {exc.strerror}")
                        continue
                    del waiting_respawn[name]
                    self.out(f"process[{name}]: started with pid [{pid}]")
            if self.master is not None and not self.master.poll():
                self.err(f"[master] {self.master.exit_description()}")
                self.shutdown.set()
            self.shutdown.wait(POLL_INTERVAL)

    def _stop_all(self) -> None:
        for proc in reversed(self.processes):
            self.out(f"[{proc.name}] killing on exit")
            proc.stop(self.sigint_timeout, self.sigterm_timeout, self.err)
        self.processes = []
        if self.master is not None:
            self.out("[master] killing on exit")
            self.master.stop(self.sigint_timeout, self.sigterm_timeout, self.err)
        self.out("shutting down processing monitor...")
        self.out("... shutting down processing monitor complete")

    # -- for rostest: the launch without its monitor loop in the caller's thread
    def start(self) -> None:
        """Start the master (when needed), set the parameters and start the nodes; then
        :meth:`monitor` in a thread of the caller's and :meth:`stop` at the end."""
        self._start_master()
        self._setup_run_id()
        self._load_parameters()
        self._start_nodes()

    def monitor(self) -> None:
        """Watch the processes (respawn, required) until :attr:`shutdown` is set."""
        self._monitor()

    def stop(self) -> None:
        self.shutdown.set()
        self._stop_all()

    # -- entry point
    def run(self, install_signal_handlers: bool = True) -> int:
        previous = {}
        if install_signal_handlers:
            # the shutdown event is set from a thread of its own, not in the handler
            # (see minros.signals)
            previous = SignalWatch(lambda _signum: self.shutdown.set(), "roslaunch-signals").install(
                (signal.SIGINT, signal.SIGTERM, signal.SIGHUP))
        try:
            try:
                self._start_master()
                if self.shutdown.is_set():
                    return 0
                self.out(f"ROS_MASTER_URI={self.master_uri}")
                self._setup_run_id()
                self._load_parameters()
                self._start_nodes()
                if not self.processes and not self.core_only and self.master is None:
                    self.out("No processes to monitor")
                    return self.exit_code
                self._monitor()
            finally:
                self._stop_all()
            self.out("done")
            return self.exit_code
        finally:
            for sig, handler in previous.items():
                signal.signal(sig, handler)


def dump_params(config: LaunchConfig) -> str:
    """``roslaunch --dump-params``: the parameters as YAML ``{key: value}``."""
    import xmlrpc.client

    import yaml

    def plain(value: Any) -> Any:
        return value.data if isinstance(value, xmlrpc.client.Binary) else value

    return yaml.safe_dump({k: plain(v) for k, v in config.params.items()}, default_flow_style=False)
