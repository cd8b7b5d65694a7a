"""roslaunch XML loader: a .launch file (and its includes) to a :class:`LaunchConfig`.

Pure apart from reading the files it names (launch, rosparam, textfile, binfile) and running
``<param command=...>``: no master, no processes. Scoping follows roslaunch: namespaces and
remaps nest through ``<group>``/``<include>``/``<node>``, ``~params`` declared in a scope
apply to the nodes that follow in it, args are per file (an include gets only the args it
is passed), and ``$(anon x)`` is one name for the whole launch. Errors carry file and line.
"""

from __future__ import annotations

import os
import shlex
import subprocess
import xml.parsers.expat
import xmlrpc.client
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Callable, Dict, List, Mapping, Sequence, Tuple

from minros import names
from minros.launch.config import LaunchConfig, LaunchError, Machine, NodeSpec
from minros.launch.rosparam_yaml import load_yaml
from minros.launch.substitution import (
    ArgError,
    SubstitutionContext,
    SubstitutionError,
    convert_value,
    resolve_args,
)

#: Upper bound for a launch or included file (they are hand-written configuration).
MAX_FILE_BYTES = 16 * 1024 * 1024
#: Deepest nesting of groups and includes accepted (real files use a handful).
MAX_NESTING = 100
#: ``<param command=...>`` must finish within this many seconds.
COMMAND_TIMEOUT = 60.0

NODE_ATTRS = ("pkg", "type", "machine", "name", "args", "output", "respawn", "respawn_delay",
              "cwd", "ns", "clear_params", "launch-prefix", "required")
TEST_ATTRS = NODE_ATTRS + ("test-name", "time-limit", "retry")
PARAM_ATTRS = ("name", "value", "type", "textfile", "binfile", "command")
ROSPARAM_ATTRS = ("command", "ns", "file", "param", "subst_value")
ARG_ATTRS = ("name", "value", "default", "doc")
REMAP_ATTRS = ("from", "to")
ENV_ATTRS = ("name", "value")
GROUP_ATTRS = ("ns", "clear_params")
INCLUDE_ATTRS = ("file", "ns", "clear_params", "pass_all_args")
MACHINE_ATTRS = ("name", "address", "env-loader", "ssh-port", "user", "password", "default", "timeout")


# ----------------------------------------------------------------------------- XML with lines

@dataclass
class Element:
    """An XML element with the line it starts on (expat gives us that; minidom does not)."""

    tag: str
    attrs: Dict[str, str]
    line: int
    children: List[Element] = field(default_factory=list)
    text: str = ""

    def has(self, attr: str) -> bool:
        return attr in self.attrs


def parse_xml(data: bytes, filename: str) -> Element:
    """Parse launch XML into :class:`Element`s; malformed XML is a LaunchError with its line."""
    parser = xml.parsers.expat.ParserCreate()
    stack: List[Element] = []
    roots: List[Element] = []

    def start(tag: str, attrs: Dict[str, str]) -> None:
        element = Element(tag, dict(attrs), parser.CurrentLineNumber)
        if stack:
            stack[-1].children.append(element)
        else:
            roots.append(element)
        stack.append(element)

    def end(_tag: str) -> None:
        stack.pop()

    def text(data_: str) -> None:
        if stack:
            stack[-1].text += data_

    parser.StartElementHandler = start
    parser.EndElementHandler = end
    parser.CharacterDataHandler = text
    # no DTDs or entities from outside: a launch file is plain XML
    parser.SetParamEntityParsing(xml.parsers.expat.XML_PARAM_ENTITY_PARSING_NEVER)
    parser.EntityDeclHandler = _refuse_entities(filename)
    try:
        parser.Parse(data, True)
    except xml.parsers.expat.ExpatError as exc:
        raise LaunchError(f"Invalid roslaunch XML syntax: {xml.parsers.expat.ErrorString(exc.code)}, "
                          f"column {exc.offset}", filename, exc.lineno) from None
    root = roots[0]
    if root.tag != "launch":
        raise LaunchError("Invalid roslaunch XML syntax: no root <launch> tag", filename, root.line)
    return root


def _refuse_entities(filename: str) -> Callable[..., None]:
    def handler(*_args: Any) -> None:
        raise LaunchError("Invalid roslaunch XML syntax: entity declarations are not allowed", filename)

    return handler


def read_launch_file(path: str) -> Element:
    try:
        with open(path, "rb") as f:
            data = f.read(MAX_FILE_BYTES + 1)
    except OSError as exc:
        raise LaunchError(f"cannot read launch file: {exc.strerror}", path) from None
    if len(data) > MAX_FILE_BYTES:
        raise LaunchError(f"launch file is larger than {MAX_FILE_BYTES} bytes", path)
    return parse_xml(data, path)


# ----------------------------------------------------------------------------- scopes

class Scope:
    """roslaunch's loader context: namespace, ~params, remaps, env, args of one scope."""

    def __init__(self, ns: str, filename: str, subst: SubstitutionContext,
                 parent: Scope | None = None, params: List[Tuple[str, Any]] | None = None,
                 env_args: List[Tuple[str, str]] | None = None,
                 arg_names: List[str] | None = None) -> None:
        self.ns = names.make_global_ns(ns or "/")
        self.filename = filename
        self.subst = subst
        self.parent = parent
        self.params: List[Tuple[str, Any]] = params if params is not None else []
        self.env_args: List[Tuple[str, str]] = env_args or []
        self.arg_names: List[str] = arg_names or []
        self.include_args: Dict[str, str] | None = None
        self.args_passed: List[str] = []
        self.pass_all_args = False
        self._remaps: List[Tuple[str, str]] = []
        self.arg_docs: Dict[str, Tuple[str | None, str | None]] = {}

    # -- tree
    def child(self, ns: str | None) -> Scope:
        if ns:
            if ns.startswith("/"):
                child_ns = ns
            elif ns == "~":
                child_ns = "~"
            else:
                child_ns = names.ns_join(self.ns, ns)
        else:
            child_ns = self.ns
        # roslaunch shares the ~params list with a child scope only when it is non-empty
        # (its `params or []`); an empty one gives the child a list of its own. Same here,
        # so a ~param declared in an include does or does not reach later nodes exactly as there.
        scope = Scope("/" if child_ns == "~" else child_ns, self.filename, self.subst.child(),
                      parent=self, params=self.params if self.params else None,
                      env_args=list(self.env_args),
                      arg_names=list(self.arg_names))
        scope.include_args = self.include_args
        return scope

    # -- remaps
    def add_remap(self, src: str, dst: str) -> None:
        src, dst = names.canonicalize_name(src), names.canonicalize_name(dst)
        if not src or not dst:
            raise ValueError("remap from/to attributes cannot be empty")
        for value, what in ((src, "from"), (dst, "to")):
            if not names.is_legal_name(value):
                raise ValueError(f"remap {what} [{value}] is not a valid ROS name")
        self._remaps = [r for r in self._remaps if r[0] != src] + [(src, dst)]

    def remap_args(self) -> List[Tuple[str, str]]:
        if self.parent is None:
            return list(self._remaps)
        own = {r[0] for r in self._remaps}
        return [r for r in self.parent.remap_args() if r[0] not in own] + list(self._remaps)

    # -- params
    def add_private_param(self, key: str, value: Any) -> None:
        self.params[:] = [p for p in self.params if p[0] != key]
        self.params.append((key, value))

    # -- args
    def add_arg(self, name: str, value: str | None, default: str | None,
                doc: str | None = None) -> None:
        if name in self.arg_names:
            if not self.pass_all_args:
                raise ValueError(f"arg '{name}' has already been declared")
        else:
            self.arg_names.append(name)
        target = self.subst.args if self.include_args is None else self.include_args
        if value is not None:
            if name in target and not self.pass_all_args:
                raise ValueError(f"cannot override arg '{name}', which has already been set")
            target[name] = value
        elif default is not None and name not in target:
            target[name] = default
        if value is None:  # what `roslaunch --ros-args` lists: settable args
            self.arg_docs[name] = (doc, default)


# ----------------------------------------------------------------------------- helpers

def _bool_attr(value: str | None, default: bool, label: str) -> bool:
    if value is None:
        return default
    if value.lower() == "true":
        return True
    if value.lower() == "false":
        return False
    if not value:
        raise ValueError(f"bool value for {label} must be non-empty")
    raise ValueError(f"invalid bool value for {label}: {value}")


def _float_attr(value: str | None, default: float, label: str) -> float:
    if value is None:
        return default
    if not value:
        raise ValueError(f"float value for {label} must be non-empty")
    try:
        return float(value)
    except ValueError:
        raise ValueError(f"invalid float value for {label}: {value}") from None


def _int_attr(value: str | None, default: int, label: str) -> int:
    if value is None or value == "":
        return default
    try:
        return int(value)
    except ValueError:
        raise ValueError(f"'{label}' must be a number: [{value}]") from None


def _run_command(command: str, name: str, env: Mapping[str, str]) -> str:
    """Output of ``<param command=...>``; Python scripts run under minros's interpreter."""
    from minros.workspace.executables import child_environment, command_for

    try:
        argv = shlex.split(command)
    except ValueError as exc:
        raise ValueError(f"Cannot load command parameter [{name}]: {exc}") from None
    if not argv:
        raise ValueError(f"Cannot load command parameter [{name}]: empty command")
    if os.path.isfile(argv[0]):
        argv = command_for(Path(argv[0])) + argv[1:]
    try:
        result = subprocess.run(argv, stdout=subprocess.PIPE, stdin=subprocess.DEVNULL,
                                env=child_environment(dict(env)), timeout=COMMAND_TIMEOUT)
    except FileNotFoundError:
        raise ValueError(f"Cannot load command parameter [{name}]: no such command [{command}]") from None
    except subprocess.TimeoutExpired:
        raise ValueError(f"Cannot load command parameter [{name}]: command [{command}] "
                         f"did not finish within {COMMAND_TIMEOUT:.0f} s") from None
    except OSError as exc:
        raise ValueError(f"Cannot load command parameter [{name}]: {exc.strerror} [{command}]") from None
    if result.returncode != 0:
        raise ValueError(f"Cannot load command parameter [{name}]: command [{command}] "
                         f"returned with code [{result.returncode}]")
    return result.stdout.decode("utf-8", "replace")


def _read_file(path: str, binary: bool = False) -> Any:
    try:
        with open(path, "rb") as f:
            data = f.read(MAX_FILE_BYTES + 1)
    except OSError as exc:
        raise ValueError(f"cannot read [{path}]: {exc.strerror}") from None
    if len(data) > MAX_FILE_BYTES:
        raise ValueError(f"[{path}] is larger than {MAX_FILE_BYTES} bytes")
    return data if binary else data.decode("utf-8", "replace")


# ----------------------------------------------------------------------------- the loader

class Loader:
    """Loads one launch (top file plus includes) into ``self.config``."""

    def __init__(self, env: Mapping[str, str] | None = None,
                 find: Callable[[str], Path | None] | None = None,
                 run_commands: bool = True, args_only: bool = False,
                 check_machines: bool = True, ignore_unset_args: bool = False) -> None:
        self.config = LaunchConfig()
        #: roslaunch's check mode: a file (or include) that uses an arg without a value stops
        #: there, keeping what came before it, instead of failing the load
        self.ignore_unset_args = ignore_unset_args
        #: False for roslaunch's loader API, whose config checks machine names later
        self.check_machines = check_machines
        self.args_only = args_only  # `roslaunch --ros-args`: read the <arg> declarations only
        self.env = os.environ if env is None else env
        self.find = find
        self.run_commands = run_commands
        self.anon: Dict[str, str] = {}
        self._stack: List[str] = []  # real paths of the files being loaded (cyclic includes)
        self._stack_names: List[str] = []  # the same files as the user named them
        self._depth = 0

    # -- entry points
    def load(self, filename: str, argv: Sequence[str] = ()) -> LaunchConfig:
        return self._load_root(read_launch_file(filename), filename, argv)

    def load_string(self, text: str, argv: Sequence[str] = (), filename: str = "<string>") -> LaunchConfig:
        return self._load_root(parse_xml(text.encode("utf-8"), filename), filename, argv)

    def _load_root(self, root: Element, filename: str, argv: Sequence[str]) -> LaunchConfig:
        subst = SubstitutionContext(args=names.load_mappings(list(argv)), anon=self.anon,
                                    filename=None if filename == "<string>" else filename,
                                    env=self.env)
        if self.find is not None:
            subst.find = self.find
        scope = Scope(names.get_ros_namespace(env=self.env), filename, subst)
        self.config.files.append(filename)
        self._stack.append(_identity(filename))
        self._stack_names.append(filename)
        try:
            self._launch_tag(root, scope)
            self._recurse(root.children, scope)
        except ArgError as exc:
            if not self.ignore_unset_args:
                raise LaunchError(f"requires the '{exc.name}' arg to be set", filename) from None
        except RecursionError:  # hundreds of nested groups/includes: refuse, do not crash
            raise LaunchError("groups and includes nest too deeply", filename) from None
        finally:
            self._stack.pop()
            self._stack_names.pop()
        self.config.arg_docs.update(scope.arg_docs)
        return self.config

    # -- generic helpers
    def _err(self, scope: Scope, el: Element, message: str) -> LaunchError:
        return LaunchError(message, scope.filename, el.line)

    def _warn(self, scope: Scope, el: Element, message: str) -> None:
        self.config.warnings.append(f"[{scope.filename}:{el.line}] {message}")

    def _resolve(self, value: str | None, scope: Scope) -> str | None:
        scope.subst.filename = None if scope.filename == "<string>" else scope.filename
        return resolve_args(value, scope.subst)

    def _opt(self, el: Element, scope: Scope, attr: str) -> str | None:
        return self._resolve(el.attrs.get(attr), scope)

    def _req(self, el: Element, scope: Scope, attr: str) -> str:
        if attr not in el.attrs:
            raise self._err(scope, el, f"<{el.tag}> tag is missing required attribute '{attr}'")
        return self._resolve(el.attrs[attr], scope) or ""

    def _check_attrs(self, el: Element, scope: Scope, allowed: Sequence[str]) -> None:
        for attr in el.attrs:
            if attr not in allowed and attr not in ("if", "unless"):
                self._warn(scope, el, f"unknown <{el.tag}> attribute '{attr}'")

    def _enabled(self, el: Element, scope: Scope) -> bool:
        """The tag's if/unless test."""
        if_val, unless_val = self._opt(el, scope, "if"), self._opt(el, scope, "unless")
        if if_val is not None and unless_val is not None:
            raise self._err(scope, el, "cannot set both 'if' and 'unless' on the same tag")
        try:
            if if_val is not None:
                return bool(convert_value(if_val, "bool"))
            if unless_val is not None:
                return not convert_value(unless_val, "bool")
        except ValueError as exc:
            raise self._err(scope, el, f"<{el.tag}> {'if' if if_val is not None else 'unless'}: {exc}") from None
        return True

    # -- tags
    def _launch_tag(self, el: Element, scope: Scope) -> None:
        deprecated = el.attrs.get("deprecated")
        if deprecated:
            self._warn(scope, el, f"DEPRECATED: {deprecated}")

    def _recurse(self, elements: List[Element], scope: Scope) -> None:
        handlers = {
            "arg": self._arg_tag, "group": self._group_tag, "node": self._node_tag,
            "test": self._test_tag, "param": self._param_tag, "remap": self._remap_tag,
            "machine": self._machine_tag, "rosparam": self._rosparam_tag,
            "include": self._include_tag, "env": self._env_tag, "master": lambda el, sc: None,
        }
        self._depth += 1
        try:
            self._recurse_elements(elements, scope, handlers)
        finally:
            self._depth -= 1

    def _recurse_elements(self, elements: List[Element], scope: Scope, handlers: Dict[str, Any]) -> None:
        if self._depth > MAX_NESTING and elements:
            raise self._err(scope, elements[0], f"groups and includes nest too deeply (more than {MAX_NESTING} levels)")
        for el in elements:
            handler = handlers.get(el.tag)
            if self.args_only and el.tag != "arg":
                continue
            if handler is None:
                self._warn(scope, el, f"unrecognized tag {el.tag}")
                continue
            try:
                if el.tag == "master" or self._enabled(el, scope):
                    handler(el, scope)
            except LaunchError:
                raise
            except ArgError:
                raise
            except (ValueError, SubstitutionError) as exc:
                raise self._err(scope, el, f"Invalid <{el.tag}> tag: {exc}") from None

    def _arg_tag(self, el: Element, scope: Scope) -> None:
        self._check_attrs(el, scope, ARG_ATTRS)
        name = self._req(el, scope, "name")
        try:
            value, default = self._opt(el, scope, "value"), self._opt(el, scope, "default")
        except ArgError as exc:
            raise self._err(scope, el, f"arg '{exc.name}' is not defined") from None
        if value is not None and default is not None:
            raise self._err(scope, el, "<arg> tag must have one and only one of value/default.")
        scope.add_arg(name, value, default, self._opt(el, scope, "doc"))

    def _ns_clear_params(self, el: Element, scope: Scope, node_name: str | None = None,
                         include_file: str | None = None) -> Scope:
        ns = None
        if el.has("ns"):
            ns = self._opt(el, scope, "ns")
            if not ns:
                raise self._err(scope, el, f"<{el.tag}> tag has an empty 'ns' attribute")
        child = scope.child(ns)
        if include_file is not None:
            child.arg_names = []
            child.filename = include_file
            child.include_args = {}
        clear = self._opt(el, scope, "clear_params")
        if clear and _bool_attr(clear, False, "clear_params"):
            if el.tag == "node":
                if not node_name:
                    raise self._err(scope, el, "<node> tag must have a 'name' attribute to use 'clear_params' attribute")
                self.config.add_clear_param(names.make_global_ns(names.ns_join(child.ns, node_name)))
            else:
                if not ns:
                    raise self._err(scope, el, "'ns' attribute must be set in order to use 'clear_params'")
                self.config.add_clear_param(child.ns)
        return child

    def _group_tag(self, el: Element, scope: Scope) -> None:
        self._check_attrs(el, scope, GROUP_ATTRS)
        child = self._ns_clear_params(el, scope)
        child.params = list(child.params)  # ~params declared in the group stay in the group
        self._recurse(el.children, child)

    def _remap_tag(self, el: Element, scope: Scope) -> None:
        self._check_attrs(el, scope, REMAP_ATTRS)
        scope.add_remap(self._req(el, scope, "from"), self._req(el, scope, "to"))

    def _env_tag(self, el: Element, scope: Scope) -> None:
        self._check_attrs(el, scope, ENV_ATTRS)
        name, value = self._req(el, scope, "name"), self._req(el, scope, "value")
        if not name:
            raise ValueError("'name' attribute must be non-empty")
        scope.env_args.append((name, value))

    def _machine_tag(self, el: Element, scope: Scope) -> None:
        if any(a.startswith("ros-") for a in el.attrs):
            raise ValueError("<machine>: ros-* attributes are not supported since ROS Fuerte.\n"
                             "Please use env-loader instead.")
        if any(c.tag == "env" for c in el.children):
            raise ValueError("<machine>: <env> tag is not supported since ROS Fuerte.\n"
                             "Please use env-loader instead.")
        self._check_attrs(el, scope, MACHINE_ATTRS)
        name, address = self._req(el, scope, "name"), self._req(el, scope, "address")
        default = (self._opt(el, scope, "default") or "false").lower()
        if default not in ("true", "false", "never"):
            raise ValueError(f"Invalid value for 'attribute': {default}")
        timeout, seconds = self._opt(el, scope, "timeout"), None
        if timeout is not None:
            if not timeout.strip():
                raise ValueError("'timeout' cannot be empty")
            try:
                seconds = float(timeout)
            except ValueError:
                raise ValueError(f"'timeout' be a number: [{timeout}]") from None
            if seconds <= 0:
                raise ValueError(f"'timeout' be a positive number: [{seconds}]")
        ssh_port = self._opt(el, scope, "ssh-port")
        self.config.machines[name] = Machine(
            name, address, default, env_loader=self._opt(el, scope, "env-loader"),
            user=self._opt(el, scope, "user"), password=self._opt(el, scope, "password"),
            ssh_port=int(ssh_port) if ssh_port else 22, timeout=seconds)

    # -- parameters
    def _param_value(self, el: Element, scope: Scope, name: str) -> Any:
        ptype = (el.attrs.get("type") or "auto").lower().strip()
        sources = {k: self._opt(el, scope, k) for k in ("value", "textfile", "binfile", "command")}
        given = [k for k, v in sources.items() if v is not None]
        if len(given) != 1:
            raise self._err(scope, el, "<param> tag must have one and only one of value/textfile/binfile.")
        kind = given[0]
        if kind == "value":
            return convert_value(sources["value"].strip(), ptype)
        if kind == "textfile":
            return convert_value(_read_file(sources["textfile"]), ptype)
        if kind == "binfile":
            return xmlrpc.client.Binary(_read_file(sources["binfile"], binary=True))
        if not self.run_commands:
            return f"<output of: {sources['command']}>"
        return convert_value(_run_command(sources["command"], name, self.env), ptype)

    def _param_tag(self, el: Element, scope: Scope, force_local: bool = False) -> None:
        self._check_attrs(el, scope, PARAM_ATTRS)
        name = self._req(el, scope, "name").strip()
        value = self._param_value(el, scope, name)
        if names.is_private(name) or force_local:
            scope.add_private_param(name, value)
        else:
            self.config.add_param(names.ns_join(scope.ns, name), value)

    def _add_tree(self, key: str, value: Any) -> None:
        """Add a parameter; dictionaries become one parameter per leaf, as roslaunch does."""
        if not key:
            raise ValueError("no parameter name specified")
        if key == "/" and not isinstance(value, dict):
            raise ValueError("Cannot load non-dictionary types into global namespace '/'")
        if isinstance(value, dict):
            for k, v in value.items():
                self._add_tree(names.ns_join(key, str(k)), v)
        else:
            self.config.add_param(key, value)

    def _rosparam_tag(self, el: Element, scope: Scope) -> None:
        self._check_attrs(el, scope, ROSPARAM_ATTRS)
        cmd = self._opt(el, scope, "command") or "load"
        ns, file_, param = (self._opt(el, scope, a) for a in ("ns", "file", "param"))
        subst_value = _bool_attr(self._opt(el, scope, "subst_value"), False, "subst_value")
        param = names.ns_join(ns or "", param or "") if (ns or param) else ""
        if cmd not in ("load", "dump", "delete"):
            raise ValueError("command must be 'load', 'dump', or 'delete'")
        if file_ is not None:
            if cmd == "load" and not os.path.isfile(file_):
                raise ValueError(f"file does not exist [{file_}]")
            if cmd == "delete":
                raise ValueError("'file' attribute is invalid with 'delete' command.")
        full = names.ns_join(scope.ns, param) if param else scope.ns
        if cmd == "dump":
            if not file_:
                raise ValueError("'file' attribute is required with 'dump' command.")
            self.config.rosparam_commands.append(("dump", file_, full))
            return
        if cmd == "delete":
            self.config.rosparam_commands.append(("delete", full))
            return
        text = _read_file(file_) if file_ else el.text
        if subst_value:
            text = self._resolve(text, scope) or ""
        try:
            data = load_yaml(text)
        except ValueError as exc:
            where = f"file {file_} contains invalid YAML" if file_ else "Error within YAML block"
            raise ValueError(f"{where}: {exc}") from None
        if data is None:
            data = {}
        if not param and not isinstance(data, dict):
            raise ValueError("'param' attribute must be set for non-dictionary values")
        self._add_tree(full, data)

    # -- nodes
    def _test_tag(self, el: Element, scope: Scope) -> None:
        self._node_tag(el, scope, is_test=True)

    def _node_tag(self, el: Element, scope: Scope, is_test: bool = False) -> None:
        if is_test:
            self._check_attrs(el, scope, TEST_ATTRS)
            for attr in ("respawn", "respawn_delay", "output"):
                if el.has(attr):
                    raise self._err(scope, el, f"<test> tags cannot have '{attr}' attribute")
            test_name = self._req(el, scope, "test-name")
            name = self._opt(el, scope, "name") or test_name
        else:
            self._check_attrs(el, scope, NODE_ATTRS)
            test_name = None
            name = self._req(el, scope, "name")
        if not names.is_legal_name(name):
            self._warn(scope, el, f"illegal <node> name '{name}' (http://ros.org/wiki/Names); "
                                  "this will likely cause problems with other ROS tools")
        child = self._ns_clear_params(el, scope, node_name=name)
        param_scope = child.child(name)
        param_scope.params = []
        pkg, node_type = self._req(el, scope, "pkg"), self._req(el, scope, "type")
        opt = {a: self._opt(el, scope, a) for a in ("machine", "args", "output", "respawn",
                                                      "respawn_delay", "cwd", "launch-prefix",
                                                      "required", "time-limit", "retry")}
        required = _bool_attr(opt["required"], False, "required")
        respawn = _bool_attr(opt["respawn"], False, "respawn")
        respawn_delay = _float_attr(opt["respawn_delay"], 0.0, "respawn_delay")
        remap_scope = scope.child("")
        env_scope = scope.child("")
        for sub in el.children:
            tag = sub.tag.lower()
            try:
                if tag in ("remap", "param", "rosparam", "env") and not self._enabled(sub, scope):
                    continue
                if tag == "remap":
                    self._remap_tag(sub, remap_scope)
                elif tag == "param":
                    self._param_tag(sub, param_scope, force_local=True)
                elif tag == "rosparam":
                    self._rosparam_tag(sub, param_scope)
                elif tag == "env":
                    self._env_tag(sub, env_scope)
                else:
                    self._warn(scope, sub, f"unrecognized '{sub.tag}' child tag in the parent tag element <{el.tag}>")
            except (ValueError, SubstitutionError) as exc:
                if isinstance(exc, ArgError):
                    raise
                raise self._err(scope, sub, f"Invalid <{sub.tag}> tag: {exc}") from None
        node_ns = param_scope.ns
        for key, value in list(scope.params) + list(param_scope.params):
            key = key[1:] if names.is_private(key) else key
            self.config.add_param(key if names.is_global(key) else node_ns + key, value)
        output, cwd = opt["output"], opt["cwd"]
        if cwd == "ros_home":
            cwd = "ROS_HOME"
        problems = [
            (respawn and required, "respawn and required cannot both be set to true"),
            ("/" in name, "node name cannot contain a namespace"),
            (not pkg.strip(), "package must be non-empty"),
            (not node_type.strip(), "type must be non-empty"),
            (output not in ("log", "screen", None), "output must be one of 'log', 'screen'"),
            (cwd not in ("ROS_HOME", "node", None), "cwd must be one of 'ROS_HOME', 'node'"),
        ]
        for bad, message in problems:
            if bad:
                raise self._err(scope, el, f"Invalid <{el.tag}> tag: {message}")
        time_limit, retry = None, 0
        if is_test:
            try:
                time_limit = _float_attr(opt["time-limit"], 60.0, "time-limit")
                if time_limit <= 0:
                    raise ValueError("'time-limit' must be a positive number")
                retry = _int_attr(opt["retry"], 0, "retry")
            except ValueError as exc:
                raise self._err(scope, el, f"Invalid <{el.tag}> tag: {exc}") from None
        machine = opt["machine"]
        if machine and self.check_machines and machine not in self.config.machines:
            raise self._err(scope, el, f"unknown machine [{machine}]")
        spec = NodeSpec(
            package=pkg, type=node_type, name=name, namespace=child.ns, args=opt["args"] or "",
            remap_args=remap_scope.remap_args(), env_args=list(env_scope.env_args), output=output,
            respawn=respawn, respawn_delay=respawn_delay, required=required, cwd=cwd,
            launch_prefix=opt["launch-prefix"] or None, machine=machine, filename=scope.filename,
            line=el.line, test_name=test_name, time_limit=time_limit, retry=retry)
        if is_test:
            self.config.tests.append(spec)
        else:
            self.config.add_node(spec)

    # -- includes
    def _include_tag(self, el: Element, scope: Scope) -> None:
        self._check_attrs(el, scope, INCLUDE_ATTRS)
        inc = self._req(el, scope, "file")
        pass_all = _bool_attr(self._opt(el, scope, "pass_all_args"), False, "pass_all_args")
        child = self._ns_clear_params(el, scope, include_file=inc)
        child.filename = scope.filename  # the include's own <arg>/<env> resolve in the parent file
        if pass_all:
            for name, value in scope.subst.args.items():
                child.add_arg(name, value, None)
            child.pass_all_args = True
        for sub in el.children:
            if sub.tag == "env":
                self._env_tag(sub, child)
            elif sub.tag == "arg":
                if self._enabled(sub, scope):
                    self._arg_tag(sub, child)
            else:
                self._warn(scope, sub, f"unrecognized '{sub.tag}' tag in <include> tag")
        child.filename = inc
        passed = child.include_args or {}
        for name in child.arg_names:
            if name not in passed:
                raise self._err(scope, el, f"include args must have declared values (arg '{name}')")
        child.args_passed = list(passed)
        child.arg_names = []
        child.subst = child.subst.child(dict(passed))
        child.include_args = None
        identity = _identity(inc)
        if identity in self._stack:
            chain = " -> ".join(self._stack_names + [inc])
            raise self._err(scope, el, f"cyclic include of [{inc}]: {chain}")
        try:
            root = read_launch_file(inc)
        except LaunchError as exc:
            if exc.line is not None:  # a syntax error inside the included file: its own place
                raise
            raise self._err(scope, el, f"cannot read included file [{inc}]: {exc.message}") from None
        self.config.files.append(inc)
        self._stack.append(identity)
        self._stack_names.append(inc)
        try:
            self._launch_tag(root, child)
            self._recurse(root.children, child)
        except ArgError as exc:
            if not self.ignore_unset_args:
                raise self._err(scope, el, f"included file [{inc}] requires the '{exc.name}' arg to be set") from None
        finally:
            self._stack.pop()
            self._stack_names.pop()
        if not pass_all:
            unused = [a for a in child.args_passed if a not in child.arg_names]
            if unused:
                raise self._err(scope, el, f"unused args [{', '.join(unused)}] for include of [{inc}]")


def _identity(path: str) -> str:
    try:
        return os.path.realpath(path)
    except OSError:
        return path


def load_launch(filename: str, argv: Sequence[str] = (), *, env: Mapping[str, str] | None = None,
                find: Callable[[str], Path | None] | None = None,
                run_commands: bool = True) -> LaunchConfig:
    """Load ``filename`` with command-line args ``argv`` (``name:=value``)."""
    return Loader(env=env, find=find, run_commands=run_commands).load(filename, argv)


def load_launch_string(text: str, argv: Sequence[str] = (), *, filename: str = "<string>",
                       env: Mapping[str, str] | None = None,
                       find: Callable[[str], Path | None] | None = None,
                       run_commands: bool = True) -> LaunchConfig:
    """Load launch XML given as text (``$(dirname)`` is unavailable unless ``filename`` is real)."""
    return Loader(env=env, find=find, run_commands=run_commands).load_string(text, argv, filename)


__all__ = ["Loader", "LaunchError", "load_launch", "load_launch_string", "parse_xml"]
