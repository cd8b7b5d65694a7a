"""roslaunch.launch: ROSLaunchRunner, roslaunch's launch over its process monitor.

The runner of roslaunch's Python API (``roslaunch.parent``, ``roslaunch.server``'s child
handler, rostest's scripts): it starts a master when none answers (``rosmaster --core``, a
core process), sets ``/run_id`` and the launch's ``/roslaunch/uris/...``, runs the setup
executables, clears and sets the parameters in two multicalls, and hands each node to the
process monitor as a :class:`minros.launch.nodeproc.LocalProcess`. minros's ``roslaunch``
command runs :class:`minros.launch.runner.LaunchRunner` instead; both start the same
commands (:func:`minros.launch.rostools.create_local_process_args`).

The stand-in ``roslaunch.launch`` *is* this module (callers replace ``printerrlog``).
"""

from __future__ import annotations

import logging
import socket
import subprocess
import sys
import time
from typing import Any, List, Optional, Tuple

from minros import names, rosenv
from minros.launch.nodeproc import (
    DEFAULT_TIMEOUT_SIGINT,
    DEFAULT_TIMEOUT_SIGTERM,
    NUM_WORKERS,
    create_master_process,
    create_node_process,
)
from minros.launch.procmon import ProcessListener, ProcessMonitor, start_process_monitor
from minros.launch.rosmodel import (  # noqa: F401 - roslaunch.launch has them too
    PHASE_RUN,
    PHASE_SETUP,
    PHASE_TEARDOWN,
    TEST_TIME_LIMIT_DEFAULT,
    RLException,
    is_machine_local,
    printerrlog,
    printlog,
    printlog_bold,
    setup_env,
)
from minros.wire.masterapi import MasterClient, MasterError, MasterFailure, RemoteError
from minros.wire.rosapi import unwrap

_TIMEOUT_MASTER_START = 10.0  # seconds
_TIMEOUT_MASTER_STOP = 10.0  # seconds
_ID = "/roslaunch"  # the caller id of the launch's master calls


def _check_all(answers: List[Any], what: str) -> None:
    """RLException naming the first of a system.multicall's answers (each ``[triplet]``, or a
    fault struct) that is no success."""
    for answer in answers:
        if isinstance(answer, dict):
            raise RLException(f"{what}: {answer.get('faultString', answer)}")
        try:
            unwrap(answer[0] if isinstance(answer, list) and len(answer) == 1 else answer)
        except RemoteError as exc:
            raise RLException(f"{what}: {exc}") from None


class RLTestTimeoutException(RLException):
    """A test node ran longer than its time-limit."""


def validate_master_launch(m: Any, is_core: bool, is_rostest: bool = False) -> None:
    """Check the master a launch is about to start: it must be on this machine (a core only
    warns), and a roscore warns when ROS_MASTER_URI names another host or port."""
    host = m.get_host()
    if not rosenv.is_local_address(host):
        if not is_core:
            raise RLException(f"ERROR: unable to contact ROS master at [{m.uri}]")
        try:
            reverse = [str(info[4][0]) for info in socket.getaddrinfo(host, 0, 0, 0, socket.SOL_TCP)]
            printerrlog(f"WARNING: IP addresses {','.join(reverse)} for local hostname '{host}' do "
                        "not appear to match\n    any local IP address "
                        f"({','.join(rosenv.get_local_addresses())}). Your ROS nodes may fail to "
                        "communicate.\n\n    Please use ROS_IP to set the correct IP address to use.")
        except Exception:  # noqa: BLE001 - the name does not resolve at all
            printerrlog(f"WARNING: local hostname '{host}' does not map to an IP address.\n    Your "
                        "ROS nodes may fail to communicate.\n\n    Please use ROS_IP to set the "
                        "correct IP address to use.")
    if is_core and not is_rostest:
        env_uri = rosenv.get_master_uri()
        env_host, env_port = rosenv.parse_http_host_and_port(env_uri)
        if not rosenv.is_local_address(env_host):
            printerrlog(f"WARNING: ROS_MASTER_URI [{env_uri}] host is not set to this machine")
        elif env_port != m.get_port():
            printerrlog(f"WARNING: ROS_MASTER_URI port [{env_port}] does not match this roscore "
                        f"[{m.get_port()}]")


def _all_namespace_parents(p: str) -> List[str]:
    """'/', '/a/', '/a/b/' for '/a/b/c'."""
    parts = [s for s in p.split("/") if s]
    return ["/"] + ["/" + "/".join(parts[:i]) + "/" for i in range(1, len(parts))]


def _unify_clear_params(params: List[str]) -> List[str]:
    """The namespaces to clear, each ending in '/', without those inside another one."""
    canon: List[str] = []
    for p in params:
        p = p if p.endswith("/") else p + "/"
        if p not in canon:
            canon.append(p)
    return [p for p in canon
            if p == "/" or not any(parent in canon for parent in _all_namespace_parents(p))]


def _hostname_to_rosname(hostname: str) -> str:
    """``host_`` and the host name, lower case, with what is not [a-z0-9] as '_'."""
    return "host_" + "".join(c if ("a" <= c <= "z" or "0" <= c <= "9") else "_"
                             for c in hostname.lower())


class _ROSLaunchListeners(ProcessListener):
    """Hands process deaths (local and remote) on to the launch's listeners."""

    def __init__(self) -> None:
        self.process_listeners: List[Any] = []

    def add_process_listener(self, listener: Any) -> None:
        self.process_listeners.append(listener)

    def process_died(self, process_name: str, exit_code: Optional[int]) -> None:
        for listener in self.process_listeners:
            try:
                listener.process_died(process_name, exit_code)
            except Exception:  # noqa: BLE001 - one listener must not silence the others
                logging.getLogger("roslaunch").exception("process listener failed")


class ROSLaunchListener:
    """Told when a process of the launch (local or remote) dies."""

    def process_died(self, process_name: str, exit_code: Optional[int]) -> None:
        """``exit_code`` None: it could not be learnt."""


class ROSLaunchRunner:
    """Runs a :class:`minros.launch.rosmodel.ROSLaunchConfig`: :meth:`launch`, then
    :meth:`spin` (or :meth:`spin_once` from a loop of one's own) until the process monitor is
    done; :meth:`stop` from another thread."""

    def __init__(self, run_id: str, config: Any, server_uri: Optional[str] = None,
                 pmon: Any = None, is_core: bool = False, remote_runner: Any = None,
                 is_child: bool = False, is_rostest: bool = False,
                 num_workers: int = NUM_WORKERS, timeout: Optional[float] = None,
                 master_logger_level: Any = False,
                 sigint_timeout: float = DEFAULT_TIMEOUT_SIGINT,
                 sigterm_timeout: float = DEFAULT_TIMEOUT_SIGTERM) -> None:
        if run_id is None:
            raise RLException("run_id is None")
        if sigint_timeout <= 0:
            raise RLException(f"sigint_timeout must be a positive number, received {sigint_timeout:f}")
        if sigterm_timeout <= 0:
            raise RLException(f"sigterm_timeout must be a positive number, received {sigterm_timeout:f}")
        self.run_id = run_id
        self.config = config
        self.server_uri = server_uri
        self.is_child = is_child
        self.is_core = is_core
        self.is_rostest = is_rostest
        self.num_workers = num_workers
        self.timeout = timeout
        self.master_logger_level = master_logger_level
        self.sigint_timeout = sigint_timeout
        self.sigterm_timeout = sigterm_timeout
        self.logger = logging.getLogger("roslaunch")
        self.pm = pmon or start_process_monitor()
        if self.pm is None:
            raise RLException("unable to initialize roslaunch process monitor")
        if self.pm.is_shutdown:
            raise RLException("bad roslaunch process monitor initialization: process monitor is already dead")
        self.listeners = _ROSLaunchListeners()
        self.pm.add_process_listener(self.listeners)
        self.remote_runner = remote_runner

    def add_process_listener(self, listener: Any) -> None:
        """Add a listener (before processes start)."""
        self.listeners.add_process_listener(listener)

    def _monitor(self) -> ProcessMonitor:
        if self.pm is None:
            raise RLException("this launch has stopped: its process monitor is shut down")
        return self.pm

    # -- the master and its parameters
    def _master(self) -> MasterClient:
        """The launch's master, called as roslaunch (``/roslaunch``)."""
        return MasterClient(self.config.master.uri, _ID)

    def _load_parameters(self) -> None:
        """Clear the launch's clear_params namespaces, then set its parameters: one multicall
        each."""
        master = self._master()
        last = None
        try:
            calls = [{"methodName": "deleteParam", "params": [_ID, ns]}
                     for ns in _unify_clear_params(self.config.clear_params)
                     if master.has_param(ns)]
            _check_all(master.multicall(calls) if calls else [], "Failed to clear parameter")
            calls = []
            for last in self.config.params.values():
                calls.append({"methodName": "setParam", "params": [_ID, last.key, last.value]})
            _check_all(master.multicall(calls) if calls else [], "Failed to set parameter")
        except RLException:
            raise
        except Exception as exc:
            printerrlog(f"load_parameters: unable to set parameters (last param was [{last}]): {exc}")
            raise
        finally:
            master.close()

    def _check_and_set_run_id(self, master: MasterClient, run_id: str) -> None:
        try:
            present = master.has_param("/run_id")
        except RemoteError:
            present = True  # then getParam tells
        if not present:
            printlog_bold(f"setting /run_id to {run_id}")
            master.set_param("/run_id", run_id)
            return
        try:
            value = master.get_param("/run_id")
        except RemoteError:
            raise RLException("ERROR: unable to retrieve /run_id from parameter server") from None
        if value != run_id:
            raise RLException(f"run_id on parameter server does not match declared run_id: "
                              f"{value} vs {run_id}")

    def _launch_master(self) -> bool:
        """Start a master unless one answers; True when this launch started it."""
        m = self.config.master
        running = m.is_running()
        if self.is_core and running:
            raise RLException("roscore cannot run as another roscore/master is already running. \n"
                              "Please kill other roscore/master processes before relaunching.\n"
                              f"The ROS_MASTER_URI is {m.uri}")
        if not running:
            validate_master_launch(m, self.is_core, self.is_rostest)
            printlog("auto-starting new master")
            p = create_master_process(self.run_id, m.type, None, m.get_port(), self.num_workers,
                                      self.timeout, master_logger_level=self.master_logger_level,
                                      sigint_timeout=self.sigint_timeout,
                                      sigterm_timeout=self.sigterm_timeout)
            self._monitor().register_core_proc(p)
            if not p.start():
                raise RLException("ERROR: unable to auto-start master process")
            deadline = time.time() + _TIMEOUT_MASTER_START
            while not m.is_running() and time.time() < deadline:
                time.sleep(0.1)
        if not m.is_running():
            raise RLException(f"ERROR: could not contact master [{m.uri}]")
        printlog_bold(f"ROS_MASTER_URI={m.uri}")
        master = self._master()
        try:
            self._check_and_set_run_id(master, self.run_id)
            if self.server_uri:
                host, port = rosenv.parse_http_host_and_port(self.server_uri)
                master.set_param(f"/roslaunch/uris/{_hostname_to_rosname(host)}__{port}",
                                 self.server_uri)
        finally:
            master.close()
        return not running

    # -- executables and nodes
    def _launch_executable(self, e: Any) -> None:
        """Run a setup executable to its end (a shell command, as roslaunch runs it)."""
        cmd = f"{e.command} {' '.join(e.args)}"
        print(f"running {cmd}")
        env = setup_env(None, self.config.machines.get(""), self.config.master.uri)
        try:
            code = subprocess.call(cmd, shell=True, env=env)
        except OSError as exc:
            raise RLException(f"command [{cmd}] failed: {exc}") from None
        if code < 0:
            raise RLException(f"command [{cmd}] failed with exit code {code}")

    def _launch_setup_executables(self) -> None:
        for e in self.config.executables:
            if e.phase == PHASE_SETUP:
                self._launch_executable(e)

    def _launch_core_nodes(self) -> None:
        """Start the core nodes (rosout) the master does not know yet."""
        master = self._master()
        pending = []
        try:
            for node in self.config.nodes_core:
                name = names.ns_join(node.namespace, node.name)
                try:
                    master.lookup_node(name)
                except MasterError:  # not known yet
                    pending.append(node)
                    continue
                except MasterFailure as exc:
                    print("WARN: master is not behaving well (unexpected return value when "
                          "looking up node)", file=sys.stderr)
                    self.logger.error("ERROR: master return [%s][%s] on lookupNode call",
                                      exc.code, exc)
                    continue
                print(f"core service [{name}] found")
        finally:
            master.close()
        for node in pending:
            name = names.ns_join(node.namespace, node.name)
            _proc, success = self.launch_node(node, core=True)
            if not success:
                raise RLException(f"failed to start core service [{name}]")
            print(f"started core service [{name}]")

    def _launch_nodes(self) -> Tuple[List[str], List[str]]:
        succeeded: List[str] = []
        failed: List[str] = []
        for node in [n for n in self.config.nodes if is_machine_local(n.machine)]:
            proc, success = self.launch_node(node)
            (succeeded if success else failed).append(str(proc))
        if self.remote_runner:
            remote_succeeded, remote_failed = self.remote_runner.launch_remote_nodes()
            succeeded.extend(remote_succeeded)
            failed.extend(remote_failed)
        return succeeded, failed

    def launch_node(self, node: Any, core: bool = False) -> Tuple[Any, bool]:
        """Start one node here (it gets a name and the local machine when it has none);
        ``(process, True)``, or ``(name, False)`` when it did not start."""
        from minros.launch.rostools import NodeParamsException

        if node.machine is None:
            node.machine = self.config.machines[""]
        if node.name is None or node.name == "":
            node.name = names.anonymous_name(node.type)
        try:
            process = create_node_process(self.run_id, node, self.config.master.uri,
                                          sigint_timeout=self.sigint_timeout,
                                          sigterm_timeout=self.sigterm_timeout)
        except NodeParamsException as exc:
            printerrlog(f"ERROR: cannot launch node of type [{node.package}/{node.type}]: {exc}")
            return (node.name or f"{node.package}/{node.type}"), False
        pm = self._monitor()
        (pm.register_core_proc if core else pm.register)(process)
        node.process_name = process.name
        success = process.start()
        if not success:
            machine_name = getattr(node.machine, "name", "")
            if machine_name:
                printerrlog(f"launch of {node.package}/{node.type} on {machine_name} failed")
            else:
                printerrlog(f"local launch of {node.package}/{node.type} failed")
        return process, success

    def is_node_running(self, node: Any) -> bool:
        name = getattr(node, "process_name", None)
        return name is not None and bool(name) and self._monitor().has_process(name)

    # -- running
    def spin_once(self) -> bool:
        if not self.pm:
            return False
        return self.pm.mainthread_spin_once()

    def spin(self) -> None:
        """Until the process monitor is done (then stop)."""
        if not self.pm or not self.pm.get_active_names():
            printlog_bold("No processes to monitor")
            self.stop()
            return
        self.pm.mainthread_spin()
        self.stop()
        printlog_bold("done")

    def stop(self) -> None:
        """Shut the process monitor down (it stops the processes) and wait for it."""
        if self.pm is None:
            return
        printlog("shutting down processing monitor...")
        self.pm.shutdown()
        self.pm.join()
        self.pm = None
        printlog("... shutting down processing monitor complete")

    def _setup(self) -> None:
        self.config.assign_machines()
        if self.remote_runner:
            self.remote_runner.add_process_listener(self.listeners)
        if self._launch_master():
            self._launch_core_nodes()
        self._launch_setup_executables()
        if not self.is_child:
            self._load_parameters()

    def launch(self) -> Tuple[List[str], List[str]]:
        """Set the graph up and start the nodes; ``(started, failed)`` process names."""
        try:
            self._setup()
            return self._launch_nodes()
        except KeyboardInterrupt:
            self.stop()
            raise

    def run_test(self, test: Any) -> None:
        """Start test node ``test`` and wait until it ends; RLTestTimeoutException after its
        time-limit."""
        _proc, success = self.launch_node(test)
        if not success:
            raise RLException(f"test [{test.test_name}] failed to launch")
        deadline = time.time() + test.time_limit
        while self._monitor().mainthread_spin_once() and self.is_node_running(test):
            if time.time() > deadline:
                raise RLTestTimeoutException(
                    f"max time [{test.time_limit}s] allotted for test [{test.test_name}] of type "
                    f"[{test.package}/{test.type}]")
            time.sleep(0.1)


class ROSRemoteRunnerIF:
    """What a runner of remote nodes offers the launch runner."""

    def __init__(self) -> None:
        pass

    def setup(self) -> None:
        """Start the remote roslaunch children."""

    def add_process_listener(self, listener: Any) -> None:
        """Listen for remote process deaths."""

    def launch_remote_nodes(self) -> Any:
        """Have the children start their nodes: ``(started, failed)``."""
