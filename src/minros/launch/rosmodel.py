"""roslaunch's data model (roslaunch.core, roslaunch.config) and its XML loader's interface
(roslaunch.xmlloader), over minros's loader.

ROS tools build a :class:`ROSLaunchConfig` by handing it to ``XmlLoader().load(file,
config)``, then read ``config.nodes``, ``config.params`` (``{key: Param}``),
``config.machines``, ``config.tests``, ``config.clear_params``, ``config.executables``. Here
the file is read by minros's loader (:mod:`minros.launch.loader`: substitutions, includes,
``if``/``unless``, rosparam YAML, every error naming file and line) and what it found is
handed to the config through roslaunch's ``add_*`` methods, as roslaunch's loader does, as
roslaunch's objects (:class:`Node`, :class:`Test`, :class:`Param`, :class:`Machine`,
:class:`RosbinExecutable`).
"""

from __future__ import annotations

import getpass
import logging
import os
import socket
import sys
import uuid
import xmlrpc.client
from typing import Any, Callable, Dict, List, Optional, Sequence, Tuple

from minros import names, packages, rosenv
from minros.launch.api import (  # noqa: F401
    Node,
    _cwd,
    _namespace,
    _xml_escape,
    node_to_xml,
    node_xmlattrs,
    validate_node,
)
from minros.launch.config import LaunchConfig, LaunchError, NodeSpec
from minros.launch.loader import Loader

RLException = LaunchError

PHASE_SETUP = "setup"
PHASE_RUN = "run"
PHASE_TEARDOWN = "teardown"
TEST_TIME_LIMIT_DEFAULT = 60.0
_DEFAULT_REGISTER_TIMEOUT = 10.0

_logger = logging.getLogger("roslaunch")

# ---------------------------------------------------------------------------------------------
# roslaunch.core


_child_mode = [False]


def is_child_mode() -> bool:
    return _child_mode[0]


def set_child_mode(child_mode: bool) -> None:
    _child_mode[0] = child_mode


_printlog_handlers: List[Callable[[str], Any]] = []
_printerrlog_handlers: List[Callable[[str], Any]] = []


def _tell(handlers: List[Callable[[str], Any]], msg: str) -> None:
    for handler in handlers:
        try:  # a handler that fails does not stop the launch
            handler(msg)
        except Exception:  # noqa: BLE001
            pass


def _print(text: str, stream: Any = None) -> None:
    try:  # nor does a console gone away (roslaunch saw errno 104 here)
        print(text, file=stream or sys.stdout)
    except Exception:  # noqa: BLE001
        pass


def printlog(msg: str) -> None:
    """Tell the printlog handlers, then print."""
    _tell(_printlog_handlers, msg)
    _print(msg)


def printlog_bold(msg: str) -> None:
    _tell(_printlog_handlers, msg)
    _print(f"\033[1m{msg}\033[0m")


def printerrlog(msg: str) -> None:
    _tell(_printerrlog_handlers, msg)
    _print(f"\033[31m{msg}\033[0m", sys.stderr)


def add_printlog_handler(h: Callable[[str], Any]) -> None:
    _printlog_handlers.append(h)


def add_printerrlog_handler(h: Callable[[str], Any]) -> None:
    _printerrlog_handlers.append(h)


def clear_printlog_handlers() -> None:
    del _printlog_handlers[:]


def clear_printerrlog_handlers() -> None:
    del _printerrlog_handlers[:]


def rle_wrapper(fn: Callable[..., Any]) -> Callable[..., Any]:
    """``fn`` as the main of a command: RLException -> one line on stderr, exit 1."""
    def wrapped(*args: Any) -> Any:
        try:
            return fn(*args)
        except RLException as exc:
            printerrlog(str(exc))
            sys.exit(1)
    return wrapped


class Master:
    """The master a launch uses (type and URI)."""

    __slots__ = ["type", "auto", "uri"]
    ROSMASTER = "rosmaster"
    ZENMASTER = "zenmaster"

    def __init__(self, type_: Optional[str] = None, uri: Optional[str] = None, auto: Any = None) -> None:
        self.auto = None
        self.type = type_ or Master.ROSMASTER
        self.uri = uri or rosenv.get_master_uri()

    def get_host(self) -> str:
        return rosenv.parse_http_host_and_port(self.uri)[0]

    def get_port(self) -> int:
        return rosenv.parse_http_host_and_port(self.uri)[1]

    def __eq__(self, other: object) -> bool:
        return isinstance(other, Master) and (other.type, other.uri) == (self.type, self.uri)

    __hash__ = None  # type: ignore[assignment]

    def get(self) -> xmlrpc.client.ServerProxy:
        return xmlrpc.client.ServerProxy(self.uri)

    def get_multi(self) -> xmlrpc.client.MultiCall:
        return xmlrpc.client.MultiCall(self.get())

    def is_running(self) -> bool:
        from minros.launch.runner import master_is_up

        return master_is_up(self.uri)


class Machine:
    """A ``<machine>``: where nodes may run."""

    __slots__ = ["name", "address", "ssh_port", "user", "password", "assignable", "env_loader",
                 "timeout"]

    def __init__(self, name: str, address: str, env_loader: Optional[str] = None,
                 ssh_port: int = 22, user: Optional[str] = None, password: Optional[str] = None,
                 assignable: bool = True, env_args: Sequence[Any] = (),
                 timeout: Optional[float] = None) -> None:
        self.name = name
        self.env_loader = env_loader
        self.user = user or None
        self.password = password
        self.address = address
        self.ssh_port = ssh_port
        self.assignable = assignable
        self.timeout = timeout or _DEFAULT_REGISTER_TIMEOUT

    def __str__(self) -> str:
        return (f"Machine(name[{self.name}] env_loader[{self.env_loader}] address[{self.address}] "
                f"ssh_port[{self.ssh_port}] user[{self.user}] assignable[{self.assignable}] "
                f"timeout[{self.timeout}])")

    def config_key(self) -> str:
        return (f"Machine(address[{self.address}] env_loader[{self.env_loader}] ssh_port["
                f"{self.ssh_port}] user[{self.user or ''}] password[{self.password or ''}] "
                f"timeout[{self.timeout}])")

    def config_equals(self, other: object) -> bool:
        return isinstance(other, Machine) and self.config_key() == other.config_key()

    def __eq__(self, other: object) -> bool:
        return isinstance(other, Machine) and self.name == other.name and \
            self.assignable == other.assignable and self.config_equals(other)

    def __ne__(self, other: object) -> bool:
        return not self == other

    __hash__ = None  # type: ignore[assignment]


class Param:
    """A parameter to set: canonical key, value."""

    def __init__(self, key: str, value: Any) -> None:
        self.key = names.canonicalize_name(key)
        self.value = value

    def __eq__(self, other: object) -> bool:
        return isinstance(other, Param) and (other.key, other.value) == (self.key, self.value)

    def __ne__(self, other: object) -> bool:
        return not self == other

    __hash__ = None  # type: ignore[assignment]

    def __str__(self) -> str:
        return f"{self.key}={self.value}"

    __repr__ = __str__


_local_machine: List[Machine] = []


def local_machine() -> Machine:
    """The machine named '' (this host)."""
    if not _local_machine:
        _local_machine.append(Machine("", "localhost"))
    return _local_machine[0]


def is_machine_local(machine: Machine) -> bool:
    """Whether ``machine`` is this host (and, with a user, this user)."""
    try:
        ips = [info[4][0] for info in socket.getaddrinfo(machine.address, 0, 0, 0, socket.SOL_TCP)]
    except socket.gaierror:
        raise RLException(f"cannot resolve host address for machine [{machine.address}]") from None
    local = ["localhost"] + rosenv.get_local_addresses()
    is_local = any(ip.startswith("127.") or ip == "::1" for ip in ips) or bool(set(ips) & set(local))
    if is_local and machine.user:
        is_local = machine.user == getpass.getuser()
    return is_local


def setup_env(node: Any, machine: Any, master_uri: str,
              env: Optional[Dict[str, str]] = None) -> Dict[str, str]:
    """The environment of a launched process: ROS_MASTER_URI, the node's namespace as
    ROS_NAMESPACE, its ``<env>`` settings."""
    d = dict(os.environ if env is None else env)
    d["ROS_MASTER_URI"] = master_uri
    if node:
        d.pop("ROS_NAMESPACE", None)
        ns = node.namespace.rstrip("/")
        if ns:
            d["ROS_NAMESPACE"] = str(ns)
        for name, value in node.env_args:
            d[str(name)] = str(value)
    return d


def remap_localhost_uri(uri: str, force_localhost: bool = False) -> str:
    """``uri`` with ``localhost`` replaced by this host's address (for remote machines)."""
    host, port = rosenv.parse_http_host_and_port(uri)
    if host == "localhost" and not force_localhost:
        return f"http://{rosenv.get_host_name()}:{port}/"
    return uri


class Test(NodeSpec):
    """A ``<test>``: a node run by rostest, with a time limit and retries."""

    def __init__(self, test_name: str, package: str, node_type: str, name: Optional[str] = None,
                 namespace: str = "/", machine_name: Optional[str] = None, args: str = "",
                 remap_args: Optional[Sequence[Tuple[str, str]]] = None,
                 env_args: Optional[Sequence[Tuple[str, str]]] = None,
                 time_limit: Optional[float] = None, cwd: Optional[str] = None,
                 launch_prefix: Optional[str] = None, retry: Optional[int] = None,
                 filename: str = "<unknown>") -> None:
        time_limit = time_limit or TEST_TIME_LIMIT_DEFAULT
        if type(time_limit) not in (int, float):
            raise ValueError("'time-limit' must be a number")
        if time_limit <= 0:
            raise ValueError("'time-limit' must be a positive number")
        super().__init__(package=package, type=node_type, name=name or "",
                         namespace=_namespace(namespace), args=args or "",
                         remap_args=list(remap_args or []), env_args=list(env_args or []),
                         output="log", cwd=_cwd(cwd), launch_prefix=launch_prefix or None,
                         machine=None, filename=filename, test_name=test_name,
                         time_limit=float(time_limit))
        self.machine_name = machine_name or None
        validate_node(self)
        self.name = name or None  # type: ignore[assignment] - roslaunch's unnamed test
        self.retry = retry or 0

    def xmltype(self) -> str:
        return "test"

    def xmlattrs(self) -> List[Tuple[str, Any]]:
        attrs = node_xmlattrs(self)
        attrs = [(a, v) for a, v in attrs if a not in ("respawn", "respawn_delay")]
        attrs.append(("test-name", self.test_name))
        if self.retry:
            attrs.append(("retry", str(self.retry)))
        if self.time_limit != TEST_TIME_LIMIT_DEFAULT:
            attrs.append(("time-limit", self.time_limit))
        return attrs

    def to_xml(self) -> str:
        return node_to_xml(self)

    def to_remote_xml(self) -> str:
        return node_to_xml(self, remote=True)


class Executable:
    """A program roslaunch runs in a phase (setup, run, teardown)."""

    def __init__(self, cmd: str, args: Sequence[str], phase: str = PHASE_RUN) -> None:
        self.command = cmd
        self.args = args
        self.phase = phase

    def __repr__(self) -> str:
        return f"{self.command} {' '.join(self.args)}"

    __str__ = __repr__


class RosbinExecutable(Executable):
    """One of ROS's own programs (rosparam ...)."""

    def __repr__(self) -> str:
        return f"ros/bin/{self.command} {' '.join(self.args)}"

    __str__ = __repr__


def generate_run_id() -> str:
    return str(uuid.uuid1())


# ---------------------------------------------------------------------------------------------
# roslaunch.config

def namespaces_of(name: str) -> List[str]:
    """``'/a/b/c'`` -> ``['/', '/a/', '/a/b/']``."""
    if name is None:
        raise ValueError("name")
    parts = [p for p in name.split("/") if p][:-1]
    return ["/"] + ["/" + "/".join(parts[:i + 1]) + "/" for i in range(len(parts))]


def _summary_name(node: Any) -> str:
    return f"{node.name} ({node.package}/{node.type})" if node.name else f"{node.package}/{node.type}"


class ROSLaunchConfig:
    """Everything a launch loaded: nodes, tests, parameters, machines, setup programs."""

    def __init__(self) -> None:
        self.roslaunch_files: List[str] = []
        self.master = Master()
        self.nodes_core: List[Any] = []
        self.nodes: List[Any] = []
        self.tests: List[Any] = []
        self.machines: Dict[str, Machine] = {"": local_machine()}
        self.params: Dict[str, Param] = {}
        self.clear_params: List[str] = []
        self.executables: List[Executable] = []
        self.config_errors: List[str] = []
        self._assign_machines_complete = False
        self._remote_nodes_present: Optional[bool] = None

    def add_roslaunch_file(self, f: str) -> None:
        if f not in self.roslaunch_files:
            self.roslaunch_files.append(f)

    def add_config_error(self, msg: str) -> None:
        self.config_errors.append(msg)

    def set_master(self, m: Master) -> None:
        self.master = m

    def has_remote_nodes(self) -> bool:
        if not self._assign_machines_complete:
            raise RLException("ERROR: has_remote_nodes() cannot be called until prelaunch check is complete")
        return bool(self._remote_nodes_present)

    def assign_machines(self) -> None:
        """Every node gets its Machine (the local one by default)."""
        if self._assign_machines_complete:
            return
        self._remote_nodes_present = False
        for node in self.nodes_core + self.nodes + self.tests:
            name = getattr(node, "machine_name", None) or ""
            machine = self.machines.get(name)
            if machine is None:
                raise RLException(f"ERROR: unknown machine [{name}]")
            node.machine = machine
            if name and not is_machine_local(machine):
                self._remote_nodes_present = True
        self._assign_machines_complete = True

    def summary(self, local: bool = False) -> str:
        out = ["", "SUMMARY", "========"]
        if self.clear_params:
            out += ["", "CLEAR PARAMETERS"] + [f" * {p}" for p in sorted(self.clear_params)]
        if self.params:
            def short(value: Any) -> str:
                text = str(value)
                return text if len(text) <= 20 else text[:17] + "..."
            out += ["", "PARAMETERS"] + [f" * {k}: {short(p.value)}" for k, p in sorted(self.params.items())]
        out += ["", "NODES"]
        by_ns: Dict[str, List[Any]] = {}
        for node in self.nodes:
            by_ns.setdefault(node.namespace, []).append(node)
        for ns in sorted(by_ns):
            out.append(f"  {ns}")
            out += sorted(f"    {_summary_name(n)}" for n in by_ns[ns])
        return "\n".join(out) + "\n"

    def add_executable(self, exe: Executable) -> None:
        self.executables.append(exe)

    def add_clear_param(self, param: str) -> None:
        self.clear_params.append(param)

    def add_param(self, p: Param, filename: Optional[str] = None, verbose: bool = True) -> None:
        """Set ``p``: a later value of one key replaces the earlier one (with a warning)."""
        key = p.key
        if key in self.params and self.params[key] != p:
            if filename:
                self.add_config_error(f"[{filename}] overriding parameter [{key}]")
            else:
                self.add_config_error(f"overriding parameter [{key}]")
        for ns in namespaces_of(key)[1:]:
            if ns.rstrip("/") in self.params:
                self.add_config_error(f"parameter [{key}] conflicts with parent parameter [{ns.rstrip('/')}]")
        self.params[key] = p
        if verbose:
            print(f"Added parameter [{key}]")

    def add_machine(self, m: Machine, verbose: bool = True) -> bool:
        """Add ``m``; RLException when its name is taken by a different configuration."""
        name = m.name
        if not name:
            name = m.name = "localhost"  # the default machine is named ''; keep it
        if name in self.machines:
            if m != self.machines[name]:
                raise RLException(f"Machine [{name}] already added and does not match duplicate entry")
            return False
        self.machines[name] = m
        if verbose:
            print(f"Added machine [{name}]")
        return True

    def add_test(self, test: Any, verbose: bool = True) -> None:
        self.tests.append(test)
        if verbose:
            print(f"Added test [{names.ns_join(test.namespace, test.name)}]")

    def add_node(self, node: Any, core: bool = False, verbose: bool = True) -> None:
        """Add ``node`` (RLException for a second node of one name)."""
        if node.name:
            resolved = names.ns_join(node.namespace, node.name)
            for other in self.nodes_core + self.nodes:
                if other.name and names.ns_join(other.namespace, other.name) == resolved:
                    message = (f"roslaunch file contains multiple nodes named [{resolved}].\n"
                               "Please check all <node> 'name' attributes to make sure they are unique.\n"
                               "Also check that $(anon id) use different ids.")
                    if core:
                        raise RLException(message)
                    raise RLException(message)
        (self.nodes_core if core else self.nodes).append(node)
        if verbose:
            print(f"Added {'core ' if core else ''}node of type [{node.package}/{node.type}] in namespace [{node.namespace}]")


# ---------------------------------------------------------------------------------------------
# roslaunch.xmlloader over minros's loader

class XmlParseException(RLException):
    """A launch file is not valid."""


class LoadException(RLException):
    """A launch file could not be loaded."""


def _ros_node(spec: NodeSpec) -> Any:
    if spec.test_name is not None:
        return Test(spec.test_name, spec.package, spec.type, name=spec.name,
                    namespace=spec.namespace, machine_name=spec.machine, args=spec.args,
                    remap_args=[list(r) for r in spec.remap_args], env_args=spec.env_args,
                    time_limit=spec.time_limit, cwd=spec.cwd, launch_prefix=spec.launch_prefix,
                    retry=spec.retry, filename=spec.filename or "<unknown>")
    return Node(spec.package, spec.type, name=spec.name or None, namespace=spec.namespace,
                machine_name=spec.machine, args=spec.args, respawn=spec.respawn,
                respawn_delay=spec.respawn_delay, remap_args=[list(r) for r in spec.remap_args],
                env_args=spec.env_args, output=spec.output, cwd=spec.cwd,
                launch_prefix=spec.launch_prefix, required=spec.required,
                filename=spec.filename or "<unknown>")


def fill_config(loaded: LaunchConfig, ros_config: Any, core: bool = False, verbose: bool = True,
                filename: Optional[str] = None) -> None:
    """Hand what minros's loader found to ``ros_config`` through roslaunch's ``add_*``."""
    for f in loaded.files:
        ros_config.add_roslaunch_file(f)
    for name, machine in loaded.machines.items():
        ros_config.add_machine(Machine(name, machine.address, env_loader=machine.env_loader,
                                       ssh_port=machine.ssh_port, user=machine.user,
                                       password=machine.password,
                                       assignable=machine.default != "never",
                                       timeout=machine.timeout), verbose)
    for ns in loaded.clear_params:
        ros_config.add_clear_param(ns)
    for command in loaded.rosparam_commands:
        ros_config.add_executable(RosbinExecutable("rosparam", list(command[:1]) + list(command[1:]),
                                                   PHASE_SETUP))
    for key, value in loaded.params.items():
        ros_config.add_param(Param(key, value), filename=filename, verbose=verbose)
    for spec in loaded.nodes:
        ros_config.add_node(_ros_node(spec), core=core, verbose=verbose)
    for spec in loaded.tests:
        ros_config.add_test(_ros_node(spec), verbose=verbose)
    for warning in loaded.warnings:
        ros_config.add_config_error(warning)


def _parse_error(exc: LaunchError) -> RLException:
    """roslaunch's exception with roslaunch's text; the place stays in ``source``. A
    <rosparam> that cannot be loaded is a LoadException, as roslaunch's loader raises it."""
    kind = LoadException if exc.message.startswith("Invalid <rosparam> tag") else XmlParseException
    error = kind(exc.message)
    error.source = (exc.filename, exc.line)  # type: ignore[attr-defined]
    return error


class XmlLoader:
    """roslaunch's loader interface: parse a launch file or string into a config object."""

    def __init__(self, resolve_anon: bool = True, args_only: bool = False) -> None:
        self.resolve_anon = resolve_anon
        self.args_only = args_only
        self.root_context = None
        #: set by load_config_default: a file using an arg without a value loads up to there
        self.ignore_unset_args = False

    def _loader(self) -> Loader:
        return Loader(check_machines=False, args_only=self.args_only,
                      ignore_unset_args=self.ignore_unset_args)

    def load(self, filename: str, ros_config: Any, core: bool = False,
             argv: Optional[Sequence[str]] = None, verbose: bool = True) -> None:
        argv = list(sys.argv if argv is None else argv)
        try:
            loaded = self._loader().load(filename, argv)
        except LaunchError as exc:
            raise _parse_error(exc) from None
        fill_config(loaded, ros_config, core, verbose, filename)

    def load_string(self, xml_text: str, ros_config: Any, core: bool = False,
                    verbose: bool = True) -> None:
        try:
            loaded = self._loader().load_string(xml_text, list(sys.argv))
        except LaunchError as exc:
            raise _parse_error(exc) from None
        fill_config(loaded, ros_config, core, verbose)


def get_roscore_filename() -> str:
    """The roscore.xml of the roslaunch package (minros's copy)."""
    from pathlib import Path

    return str(Path(__file__).resolve().parent / "share" / "roscore.xml")


def load_roscore(loader: XmlLoader, config: ROSLaunchConfig, verbose: bool = True) -> None:
    """The nodes and parameters roscore adds to every launch: rosout (a core node), and
    /rosversion and /rosdistro, which ROS's roscore.xml gets from the rosversion program."""
    path = get_roscore_filename()
    if not os.path.isfile(path):
        raise RLException(f"Unable to locate roscore.xml file: {path}")
    loader.load(path, config, core=True, verbose=verbose)
    folder = packages.find_package("roslaunch")
    version = (packages.manifest_version(folder) if folder is not None else None) or "1.15.15"
    config.add_param(Param("/rosversion", f"{version}\n"), verbose=verbose)
    config.add_param(Param("/rosdistro", f"{os.environ.get('ROS_DISTRO') or 'noetic'}\n"),
                     verbose=verbose)


def calculate_env_loader(env: Optional[Dict[str, str]] = None) -> Optional[str]:
    """ROS_ENV_LOADER, the script a remote machine sources (None when unset)."""
    return (os.environ if env is None else env).get("ROS_ENV_LOADER")


def load_config_default(roslaunch_files: Sequence[Any], port: Optional[int],
                        roslaunch_strs: Optional[Sequence[str]] = None,
                        loader: Optional[XmlLoader] = None, verbose: bool = False,
                        assign_machines: bool = True, ignore_unset_args: bool = False) -> ROSLaunchConfig:
    """A config from launch files (or ``(file, [args])`` pairs) and XML strings."""
    loader = loader or XmlLoader()
    loader.ignore_unset_args = ignore_unset_args
    config = ROSLaunchConfig()
    if port:
        host = rosenv.parse_http_host_and_port(config.master.uri)[0]
        config.master.uri = f"http://{host}:{port}/"
    load_roscore(loader, config, verbose=verbose)  # first: later declarations win
    for item in roslaunch_files:
        path, args = (item if isinstance(item, (list, tuple)) else (item, []))
        if not os.path.isfile(path):
            raise RLException(f"ERROR: roslaunch file [{path}] does not exist")
        config.add_roslaunch_file(path)
        loader.load(path, config, argv=[sys.argv[0], *args] if args else None, verbose=verbose)
    for text in roslaunch_strs or ():
        loader.load_string(text, config, verbose=verbose)
    if assign_machines:
        config.assign_machines()
    return config


# ---------------------------------------------------------------------------------------------
# roslaunch.substitution_args

class SubstitutionException(RLException):
    """A ``$(...)`` that cannot be resolved."""


class ArgException(SubstitutionException):
    """``$(arg x)`` of an undeclared argument."""


def _context(context: Optional[Dict[str, Any]], filename: Optional[str] = None) -> Any:
    """A minros substitution context over a roslaunch context dict (``arg``, ``anon``,
    ``filename``); the dict's ``anon`` and ``arg`` tables are shared, as in roslaunch."""
    from minros.launch import substitution

    context = {} if context is None else context
    return substitution.SubstitutionContext(
        args=context.setdefault("arg", {}), anon=context.setdefault("anon", {}),
        filename=filename or context.get("filename") or "")


def _substituting(fn: Callable[[], Any]) -> Any:
    from minros.launch import substitution

    try:
        return fn()
    except substitution.ArgError as exc:
        raise ArgException(str(exc)) from None
    except substitution.SubstitutionError as exc:
        raise SubstitutionException(str(exc)) from None


def resolve_args(arg_str: Optional[str], context: Optional[Dict[str, Any]] = None,
                 resolve_anon: bool = True, filename: Optional[str] = None) -> Optional[str]:
    """Resolve the ``$(env)``, ``$(optenv)``, ``$(find)``, ``$(anon)``, ``$(arg)``,
    ``$(dirname)`` and ``$(eval)`` substitutions of ``arg_str``; ``context['arg']`` holds the
    arguments, ``context['anon']`` the anonymous names given so far."""
    from minros.launch import substitution

    ctx = _context(context, filename)
    return _substituting(lambda: substitution.resolve_args(arg_str, ctx))


def _command(command: str) -> Callable[[str, str, List[str], Dict[str, Any]], str]:
    """roslaunch's handler of one substitution command: ``(resolved, a, args, context)`` ->
    ``resolved`` with ``$(a)`` replaced."""
    def handler(resolved: str, a: str, args: List[str], context: Dict[str, Any]) -> str:
        from minros.launch import substitution

        ctx = _context(context)
        return _substituting(lambda: substitution._apply(resolved, a, ctx, (command,)))
    handler.__name__ = handler.__qualname__ = "_" + command
    return handler


_env, _optenv, _anon, _dirname, _arg, _find = (
    _command(c) for c in ("env", "optenv", "anon", "dirname", "arg", "find"))


def _collect_args(arg_str: str) -> List[str]:
    from minros.launch import substitution

    return _substituting(lambda: substitution.collect_args(arg_str))


def packages_of(config: ROSLaunchConfig) -> List[str]:
    """The packages whose programs a config runs."""
    return sorted({n.package for n in config.nodes + config.tests})


def missing_packages(config: ROSLaunchConfig) -> List[str]:
    return [p for p in packages_of(config) if packages.find_package(p) is None]
