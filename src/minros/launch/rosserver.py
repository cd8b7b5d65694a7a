"""roslaunch.server, child, parent and remote: roslaunch's parent/child process API.

A parent roslaunch (:class:`ROSLaunchParent`) loads the launch files, starts a process
monitor and an XML-RPC server (:class:`ROSLaunchParentNode`: ``get_pid``, ``list_processes``,
``process_info``, ``get_node_names``, and for children ``register``, ``list_children``,
``process_died``, ``log``), then a :class:`minros.launch.rosrunner.ROSLaunchRunner`. A child
(:class:`ROSLaunchChild`) serves ``launch(xml)`` (:class:`ROSLaunchChildNode`), registers with
its parent and forwards its logs and process deaths there. The servers are minros's XML-RPC
servers (:class:`minros.wire.xmlrpc_node.XmlRpcNode`).

Remote machines: minros runs nodes on this machine only, so :class:`ROSRemoteRunner` refuses
to start children over SSH with one line saying so.
"""

from __future__ import annotations

import logging
import os
import time
import traceback
import xmlrpc.client
from typing import Any, Dict, List, Optional

from minros import rosenv
from minros.launch.nodeproc import DEFAULT_TIMEOUT_SIGINT, DEFAULT_TIMEOUT_SIGTERM, NUM_WORKERS
from minros.launch.procmon import (
    Process,
    ProcessListener,
    _init_signal_handlers,
    start_process_monitor,
)
from minros.launch.rosmodel import (
    RLException,
    ROSLaunchConfig,
    XmlLoader,
    XmlParseException,
    add_printerrlog_handler,
    add_printlog_handler,
    is_machine_local,
    load_config_default,
    printerrlog,
    printlog,
    printlog_bold,
    set_child_mode,
)
from minros.launch.rosrunner import ROSLaunchRunner, ROSRemoteRunnerIF
from minros.wire.rosapi import RemoteError, unwrap
from minros.wire.xmlrpc_node import XmlRpcHandler, XmlRpcNode

# rosgraph_msgs/Log levels
_LOG_INFO, _LOG_ERROR = 2, 8

_STARTUP_TIMEOUT = 5.0  # seconds for a server to answer itself
_CHILD_REGISTER_TIMEOUT = 10.0  # seconds


class ChildROSLaunchProcess(Process):
    """A child roslaunch as the parent's process monitor sees it; ``uri`` once registered."""

    def __init__(self, name: str, args: Any, env: Any) -> None:
        super().__init__("roslaunch", name, args, env, False)
        self.uri: Optional[str] = None

    def set_uri(self, uri: str) -> None:
        self.uri = uri


# -- roslaunch.remoteprocess ----------------------------------------------------------------

TIMEOUT_SSH_CONNECT = 30.0  # seconds roslaunch gives an SSH connection

_SSH_UNKNOWN_TEXT = """{host} is not in your SSH known_hosts file.

Please manually:
  ssh {port}{user}{host}

then try roslaunching again.

If you wish to configure roslaunch to automatically recognize unknown
hosts, please set the environment variable ROSLAUNCH_SSH_UNKNOWN=1"""


def _known_host_patterns(line: str) -> List[str]:
    """The host patterns of one known_hosts line (``@cert-authority`` markers skipped)."""
    fields = line.split()
    if fields and fields[0].startswith("@"):
        fields = fields[1:]
    return fields[0].split(",") if len(fields) >= 3 else []


def _known_host_matches(pattern: str, host: str, port: int) -> bool:
    import base64
    import hashlib
    import hmac
    import re

    wanted = host if port == 22 else f"[{host}]:{port}"
    if pattern.startswith("|1|"):  # hashed: |1|base64(salt)|base64(HMAC-SHA1(salt, host))
        try:
            _, _, salt, digest = pattern.split("|")
            mac = hmac.new(base64.b64decode(salt), wanted.encode(), hashlib.sha1).digest()
            return hmac.compare_digest(mac, base64.b64decode(digest))
        except (ValueError, TypeError):
            return False
    # OpenSSH's wildcards are '*' and '?' only ('[host]:port' is literal)
    regex = re.escape(pattern).replace(r"\*", ".*").replace(r"\?", ".")
    return not pattern.startswith("!") and re.fullmatch(regex, wanted) is not None


def is_known_host(host: str, port: int = 22, files: Optional[List[str]] = None) -> bool:
    """Whether ``host`` has a key in the system's or the user's SSH known_hosts file."""
    files = files if files is not None else [
        "/etc/ssh/ssh_known_hosts", os.path.join(os.path.expanduser("~"), ".ssh", "known_hosts")]
    for path in files:
        try:
            with open(path, encoding="utf-8", errors="replace") as f:
                lines = f.read().splitlines()
        except OSError:
            continue
        for line in lines:
            if line.strip() and not line.lstrip().startswith("#") and any(
                    _known_host_matches(p, host, port) for p in _known_host_patterns(line)):
                return True
    return False


def ssh_check_known_hosts(ssh: Any, address: str, port: int, username: Optional[str] = None,
                          logger: Any = None) -> Optional[str]:
    """roslaunch's advice when ``address`` is not in the SSH known_hosts files (None when it
    is, or when ROSLAUNCH_SSH_UNKNOWN=1 accepts unknown hosts). ``ssh`` (paramiko's client in
    ROS) is not used: minros reads the known_hosts files itself."""
    if os.environ.get("ROSLAUNCH_SSH_UNKNOWN", "0") == "1" or is_known_host(address, port):
        return None
    return _SSH_UNKNOWN_TEXT.format(host=address, port=f"-p {port} " if port != 22 else "",
                                    user=f"{username}@" if username else "")


class SSHChildROSLaunchProcess(ChildROSLaunchProcess):
    """A child roslaunch on another machine, which roslaunch starts over SSH. minros launches
    on this machine only: the command line is built as roslaunch's, ``start()`` says why it
    cannot run it and returns False, as roslaunch does when the SSH connection fails."""

    def __init__(self, run_id: str, name: str, server_uri: str, machine: Any,
                 master_uri: Optional[str] = None,
                 sigint_timeout: float = DEFAULT_TIMEOUT_SIGINT,
                 sigterm_timeout: float = DEFAULT_TIMEOUT_SIGTERM) -> None:
        if not getattr(machine, "env_loader", None):
            raise ValueError("machine.env_loader must have been assigned before creating ssh "
                             "child instance")
        args = [machine.env_loader, "roslaunch", "-c", name, "-u", server_uri, "--run_id", run_id,
                "--sigint-timeout", str(sigint_timeout), "--sigterm-timeout", str(sigterm_timeout)]
        super().__init__(name, args, {})
        self.machine = machine
        self.master_uri = master_uri
        self.sigint_timeout = sigint_timeout
        self.sigterm_timeout = sigterm_timeout
        self.ssh = self.sshin = self.sshout = self.ssherr = None
        self.started = False
        self.is_dead = False

    def start(self) -> bool:
        m = self.machine
        printerrlog(f"remote[{self.name}]: failed to launch on {m.name}:\n\n"
                    f"minros launches nodes on this machine only; it does not start roslaunch "
                    f"over SSH on [{m.address}]. Start a roslaunch there yourself, or drop "
                    f"machine=\"{m.name}\" from the launch file.\n\n")
        self.started = True
        return False

    def getapi(self) -> Any:
        return xmlrpc.client.ServerProxy(self.uri) if self.uri else None

    def is_alive(self) -> bool:
        return not self.started  # not started counts as alive, as in roslaunch

    def stop(self, errors: Optional[List[str]] = None) -> None:
        self.ssh = self.sshin = self.sshout = self.ssherr = None


# -- XML-RPC handlers ------------------------------------------------------------------------

class ROSLaunchBaseHandler(XmlRpcHandler):
    """The XML-RPC API of parents and children alike."""

    def __init__(self, pm: Any) -> None:
        self.pm = pm
        self.logger = logging.getLogger("roslaunch.server")
        if self.pm is None:
            raise RLException("cannot create xmlrpc handler: pm is not initialized")

    def list_processes(self) -> Any:
        """``[[(name, spawn count) alive], [... dead]]``."""
        return 1, "processes on parent machine", self.pm.get_process_names_with_spawn_count()

    def process_info(self, process_name: str) -> Any:
        p = self.pm.get_process(process_name)
        if p is None:
            return -1, "no process by that name", {}
        return 1, "process info", p.get_info()

    def get_pid(self) -> Any:
        pid = os.getpid()
        return 1, str(pid), pid

    def get_node_names(self) -> Any:
        if self.pm is None:
            return 0, "uninitialized", []
        return 1, "node names", self.pm.get_active_names()

    def _shutdown(self, reason: str) -> Any:
        return 1, "", 1


class ROSLaunchParentHandler(ROSLaunchBaseHandler):
    """The parent's API: children register, report deaths and log through it."""

    def __init__(self, pm: Any, child_processes: Dict[str, ChildROSLaunchProcess],
                 listeners: List[Any]) -> None:
        super().__init__(pm)
        self.child_processes = child_processes
        self.listeners = listeners

    def register(self, client: str, uri: str) -> Any:
        if client not in self.child_processes:
            self.logger.error("Unknown child [%s] registered with server", client)
            return -1, f"unknown child [{client}]", 0
        self.child_processes[client].set_uri(uri)
        return 1, "registered", 1

    def list_children(self) -> Any:
        return 1, "roslaunch children", [p.uri for p in self.child_processes.values()
                                         if p.uri is not None]

    def process_died(self, process_name: str, exit_code: Any) -> Any:
        for listener in self.listeners:
            try:
                listener.process_died(process_name, exit_code)
            except Exception:  # noqa: BLE001
                self.logger.error(traceback.format_exc())
        return 1, "", 0

    def log(self, client: str, level: int, message: str) -> Any:
        try:
            if level >= _LOG_ERROR:
                printerrlog(f"[{client}]: {message}")
            elif "started with pid" in message:
                printlog_bold(f"[{client}]: {message}")
            else:
                printlog(f"[{client}]: {message}")
        except Exception:  # noqa: BLE001
            traceback.print_exc()
        return 1, "", 1


class ROSLaunchChildHandler(ROSLaunchBaseHandler):
    """A child's API: ``launch(xml)`` starts nodes under the child's process monitor."""

    def __init__(self, run_id: str, name: str, server_uri: Optional[str], pm: Any,
                 sigint_timeout: float = DEFAULT_TIMEOUT_SIGINT,
                 sigterm_timeout: float = DEFAULT_TIMEOUT_SIGTERM) -> None:
        super().__init__(pm)
        if server_uri is None:
            raise RLException("server_uri is not initialized")
        _host, port = rosenv.parse_http_host_and_port(server_uri)
        if port <= 0:
            raise RLException(f"ERROR: roslaunch server URI is not a valid XML-RPC URI. Value is "
                              f"[{server_uri}]")
        self.run_id = run_id
        self.name = name
        self.server_uri = server_uri
        self.sigint_timeout = sigint_timeout
        self.sigterm_timeout = sigterm_timeout
        self.server = xmlrpc.client.ServerProxy(server_uri)

    def _shutdown(self, reason: str) -> Any:
        if self.pm is not None:
            self.pm.shutdown()
            self.pm.join()
            self.pm = None

    def shutdown(self) -> Any:
        self._shutdown("external call")
        return 1, "success", 1

    def _log(self, level: int, message: str) -> None:
        """Log to the child's log and to the parent."""
        try:
            self.logger.debug(message)
            if self.server is not None:
                self.server.log(str(self.name), level, str(message))
        except Exception:  # noqa: BLE001 - the parent may be gone
            self.logger.error(traceback.format_exc())

    def launch(self, launch_xml: str) -> Any:
        """Start the nodes of ``launch_xml`` here (no parameters, no master: the parent's);
        blocks until they are started."""
        if self.pm is None:
            return 0, "uninitialized", -1
        config = ROSLaunchConfig()
        try:
            XmlLoader().load_string(launch_xml, config, verbose=False)
        except XmlParseException as exc:
            return -1, f"ERROR: {exc}", [[], []]
        config.assign_machines()
        try:
            self._log(_LOG_INFO, "launching nodes...")
            runner = ROSLaunchRunner(self.run_id, config, server_uri=self.server_uri, pmon=self.pm,
                                     sigint_timeout=self.sigint_timeout,
                                     sigterm_timeout=self.sigterm_timeout)
            succeeded, failed = runner.launch()
            self._log(_LOG_INFO, "... done launching nodes")
            self.pm.registrations_complete()
            return 1, "launched", [succeeded, failed]
        except Exception:  # noqa: BLE001 - the parent gets the trace
            return 0, f"ERROR: {traceback.format_exc()}", [[], []]


# -- servers ---------------------------------------------------------------------------------

class ROSLaunchNode(XmlRpcNode):
    """The XML-RPC server of a parent or child roslaunch, on any free port."""

    def __init__(self, handler: Any) -> None:
        super().__init__(0, handler)

    def start(self) -> None:
        """Serve, and check that the server answers this process before going on."""
        super().start()
        deadline = time.time() + _STARTUP_TIMEOUT
        while not self.uri and time.time() < deadline:
            time.sleep(0.01)
        if not self.uri:
            raise RLException("XML-RPC initialization failed")
        while True:
            try:
                _code, _msg, pid = xmlrpc.client.ServerProxy(self.uri).get_pid()
            except OSError:
                if time.time() > deadline:
                    host = rosenv.parse_http_host_and_port(self.uri)[0]
                    raise RLException(
                        f"Unable to contact my own server at [{self.uri}].\nThis usually means that "
                        "the network is not configured properly.\nA common cause is that the machine "
                        "cannot connect to itself.  Please check\nfor errors by running:\n\n"
                        f"\tping {host}\n\nFor more tips, please see\n\n"
                        "\thttp://wiki.ros.org/ROS/NetworkSetup\n") from None
                time.sleep(0.1)
                continue
            if pid != os.getpid():
                raise RLException(f"Server at [{self.uri}] did not respond with correct PID. There "
                                  "appears to be something wrong with the networking configuration")
            break
        printlog_bold(f"started roslaunch server {self.uri}")


class ROSLaunchParentNode(ROSLaunchNode):
    """The parent's server; children are added before they register."""

    def __init__(self, rosconfig: Any, pm: Any) -> None:
        self.rosconfig = rosconfig
        self.listeners: List[Any] = []
        self.child_processes: Dict[str, ChildROSLaunchProcess] = {}
        if pm is None:
            raise RLException("cannot create parent node: pm is not initialized")
        super().__init__(ROSLaunchParentHandler(pm, self.child_processes, self.listeners))

    def add_child(self, name: str, p: ChildROSLaunchProcess) -> None:
        self.child_processes[name] = p

    def add_process_listener(self, listener: Any) -> None:
        """Listen for remote process deaths (before processes start)."""
        self.listeners.append(listener)


class _ProcessListenerForwarder(ProcessListener):
    """Tells the parent's server about a child's process deaths."""

    def __init__(self, server: Any) -> None:
        self.server = server

    def process_died(self, process_name: str, exit_code: Any) -> None:
        try:
            self.server.process_died(process_name, exit_code)
        except Exception:  # noqa: BLE001
            logging.getLogger("roslaunch.remote").error(traceback.format_exc())


class ROSLaunchChildNode(ROSLaunchNode):
    """A child's server: registers with the parent once it serves."""

    def __init__(self, run_id: str, name: str, server_uri: str, pm: Any,
                 sigint_timeout: float = DEFAULT_TIMEOUT_SIGINT,
                 sigterm_timeout: float = DEFAULT_TIMEOUT_SIGTERM) -> None:
        self.logger = logging.getLogger("roslaunch.server")
        self.run_id = run_id
        self.name = name
        self.server_uri = server_uri
        self.pm = pm
        if self.pm is None:
            raise RLException("cannot create child node: pm is not initialized")
        super().__init__(ROSLaunchChildHandler(run_id, name, server_uri, pm,
                                               sigint_timeout=sigint_timeout,
                                               sigterm_timeout=sigterm_timeout))

    def _register_with_server(self) -> None:
        name = self.name
        try:
            server = xmlrpc.client.ServerProxy(self.server_uri)
            try:
                unwrap(server.register(name, self.uri))
            except RemoteError as exc:
                raise RLException(f"unable to register with roslaunch server: {exc}") from None
        except Exception:
            raise RLException(f"Exception while registering with roslaunch parent "
                              f"[{self.server_uri}]: {traceback.format_exc()}") from None
        add_printlog_handler(lambda msg: server.log(name, _LOG_INFO, msg))
        add_printerrlog_handler(lambda msg: server.log(name, _LOG_ERROR, msg))
        self.pm.add_process_listener(_ProcessListenerForwarder(server))

    def start(self) -> None:
        super().start()
        self._register_with_server()


# -- roslaunch.child -------------------------------------------------------------------------

class ROSLaunchChild:
    """A child roslaunch: serves its parent until told to stop."""

    def __init__(self, run_id: str, name: str, server_uri: str,
                 sigint_timeout: float = DEFAULT_TIMEOUT_SIGINT,
                 sigterm_timeout: float = DEFAULT_TIMEOUT_SIGTERM) -> None:
        set_child_mode(True)
        self.logger = logging.getLogger("roslaunch.child")
        self.run_id = run_id
        self.name = name
        self.server_uri = server_uri
        self.child_server: Optional[ROSLaunchChildNode] = None
        self.pm: Any = None
        self.sigint_timeout = sigint_timeout
        self.sigterm_timeout = sigterm_timeout
        _init_signal_handlers()

    def _start_pm(self) -> None:
        if self.pm is None:
            self.pm = start_process_monitor()
        if self.pm is None:
            raise RLException("cannot startup remote child: unable to start process monitor.")

    def run(self) -> None:
        """Serve until the process monitor is done."""
        try:
            self._start_pm()
            self.child_server = ROSLaunchChildNode(self.run_id, self.name, self.server_uri, self.pm,
                                                   sigint_timeout=self.sigint_timeout,
                                                   sigterm_timeout=self.sigterm_timeout)
            self.child_server.start()
            self.pm.mainthread_spin()
        except Exception:
            self.logger.error(traceback.format_exc())
            raise
        finally:
            if self.pm:
                self.pm.shutdown()
                self.pm.join()
            if self.child_server:
                self.child_server.shutdown("roslaunch child complete")

    def shutdown(self) -> None:
        if self.pm:
            self.pm.shutdown()
            self.pm.join()


# -- roslaunch.remote ------------------------------------------------------------------------

class ROSRemoteRunner(ROSRemoteRunnerIF):
    """Starts the nodes of remote machines through child roslaunches, which roslaunch starts
    over SSH; minros launches on this machine only and says so when asked to start one."""

    def __init__(self, run_id: str, rosconfig: Any, pm: Any, server: Any,
                 sigint_timeout: float = DEFAULT_TIMEOUT_SIGINT,
                 sigterm_timeout: float = DEFAULT_TIMEOUT_SIGTERM) -> None:
        self.run_id = run_id
        self.rosconfig = rosconfig
        self.server = server
        self.pm = pm
        self.sigint_timeout = sigint_timeout
        self.sigterm_timeout = sigterm_timeout
        self.logger = logging.getLogger("roslaunch.remote")
        self.listeners: List[Any] = []
        self.machine_list: List[Any] = []
        self.remote_processes: List[Any] = []

    def add_process_listener(self, listener: Any) -> None:
        self.listeners.append(listener)

    def start_children(self) -> None:
        if not self.server.uri:
            raise RLException("server URI is not initialized")
        remote = {n.machine.config_key(): n.machine for n in self.rosconfig.nodes
                  if not is_machine_local(n.machine)}
        if remote:
            listing = ", ".join(sorted(m.name for m in remote.values()))
            raise RLException(f"cannot launch nodes on machines [{listing}]: minros launches on "
                              "this machine only (no SSH children)")

    def launch_remote_nodes(self) -> Any:
        return [], []


# -- roslaunch.parent ------------------------------------------------------------------------

class ROSLaunchParent:
    """A roslaunch from Python: ``start()``, then ``spin()`` (or ``spin_once()`` in a loop of
    one's own), ``shutdown()`` from anywhere."""

    def __init__(self, run_id: str, roslaunch_files: Any, is_core: bool = False,
                 port: Optional[int] = None, local_only: bool = False,
                 process_listeners: Any = None, verbose: bool = False, force_screen: bool = False,
                 force_log: bool = False, is_rostest: bool = False, roslaunch_strs: Any = None,
                 num_workers: int = NUM_WORKERS, timeout: Optional[float] = None,
                 master_logger_level: Any = False, show_summary: bool = True,
                 force_required: bool = False, sigint_timeout: float = DEFAULT_TIMEOUT_SIGINT,
                 sigterm_timeout: float = DEFAULT_TIMEOUT_SIGTERM) -> None:
        if sigint_timeout <= 0:
            raise RLException(f"sigint_timeout must be a positive number, received {sigint_timeout:f}")
        if sigterm_timeout <= 0:
            raise RLException(f"sigterm_timeout must be a positive number, received {sigterm_timeout:f}")
        self.logger = logging.getLogger("roslaunch.parent")
        self.run_id = run_id
        self.process_listeners = process_listeners
        self.roslaunch_files = roslaunch_files
        self.roslaunch_strs = roslaunch_strs
        self.is_core = is_core
        self.is_rostest = is_rostest
        self.port = port
        self.local_only = local_only
        self.verbose = verbose
        self.show_summary = show_summary
        self.num_workers = num_workers
        self.timeout = timeout
        self.master_logger_level = master_logger_level
        self.sigint_timeout = sigint_timeout
        self.sigterm_timeout = sigterm_timeout
        self.force_screen = force_screen
        self.force_log = force_log
        self.force_required = force_required
        self._shutting_down = False
        self.config: Any = None
        self.runner: Optional[ROSLaunchRunner] = None
        self.server: Optional[ROSLaunchParentNode] = None
        self.pm: Any = None
        self.remote_runner: Optional[ROSRemoteRunner] = None

    def _load_config(self) -> None:
        self.config = load_config_default(self.roslaunch_files, self.port,
                                          roslaunch_strs=self.roslaunch_strs, verbose=self.verbose)
        for node in self.config.nodes:
            if self.force_screen:
                node.output = "screen"
            if self.force_log:
                node.output = "log"
            if self.force_required:
                node.required = True
                if node.respawn:
                    raise ValueError("respawn and required cannot both be set to true")

    def _start_pm(self) -> None:
        self.pm = start_process_monitor()

    def _require(self, *what: str) -> None:
        for name in what:
            if getattr(self, name) is None:
                raise RLException(f"{name} is not initialized")

    def _init_runner(self) -> None:
        self._require("config", "pm", "server")
        assert self.server is not None
        self.runner = ROSLaunchRunner(
            self.run_id, self.config, server_uri=self.server.uri, pmon=self.pm,
            is_core=self.is_core, remote_runner=self.remote_runner, is_rostest=self.is_rostest,
            num_workers=self.num_workers, timeout=self.timeout,
            master_logger_level=self.master_logger_level, sigint_timeout=self.sigint_timeout,
            sigterm_timeout=self.sigterm_timeout)
        if self.is_core and "/rosversion" in self.config.params:
            print(f"ros_comm version {self.config.params['/rosversion'].value}")
        if self.show_summary:
            print(self.config.summary(local=self.remote_runner is None))
        for error in self.config.config_errors:
            printerrlog(f"WARNING: {error}")

    def _start_server(self) -> None:
        self._require("config", "pm")
        self.server = ROSLaunchParentNode(self.config, self.pm)
        self.server.start()
        if not self.server.uri:
            raise RLException("server URI did not initialize")

    def _init_remote(self) -> None:
        self._require("config", "pm", "server")
        if not self.local_only and self.config.has_remote_nodes():
            self.remote_runner = ROSRemoteRunner(self.run_id, self.config, self.pm, self.server,
                                                 sigint_timeout=self.sigint_timeout,
                                                 sigterm_timeout=self.sigterm_timeout)
        elif self.local_only:
            printlog_bold("LOCAL\nlocal only launch specified, will not launch remote nodes\nLOCAL\n")

    def _start_remote(self) -> None:
        if self.remote_runner is None:
            self._init_remote()
        if self.remote_runner is not None:
            self.remote_runner.start_children()

    def _start_infrastructure(self) -> None:
        if self.config is None:
            self._load_config()
        if self.pm is None:
            self._start_pm()
        if self.server is None:
            self._start_server()
        self._start_remote()

    def _stop_infrastructure(self) -> None:
        if self._shutting_down:
            return
        self._shutting_down = True
        if self.server:
            try:
                self.server.shutdown("roslaunch parent complete")
            except Exception:  # noqa: BLE001
                pass
        if self.pm:
            self.pm.shutdown()
            self.pm.join()

    def start(self, auto_terminate: bool = True) -> None:
        """Load, start the monitor and server, then the master (if needed) and the nodes.
        With ``auto_terminate``, the launch ends when its last process does."""
        try:
            self._start_infrastructure()
        except BaseException:
            self._stop_infrastructure()
            raise
        self._init_runner()
        assert self.runner is not None and self.server is not None
        self.runner.launch()
        if auto_terminate:
            self.pm.registrations_complete()
        for listener in self.process_listeners or ():
            self.runner.pm.add_process_listener(listener)
            self.server.add_process_listener(listener)

    def spin_once(self) -> None:
        if self.runner:
            self.runner.spin_once()

    def spin(self) -> None:
        """Until the launch ends (then shut down)."""
        if not self.runner:
            raise RLException("parent not started yet")
        try:
            self.runner.spin()
        finally:
            self._stop_infrastructure()

    def shutdown(self) -> None:
        self._stop_infrastructure()
