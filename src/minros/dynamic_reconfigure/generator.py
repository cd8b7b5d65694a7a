"""``.cfg`` scripts to ``<pkg>.cfg.<Name>Config`` modules, without a build step.

A ``.cfg`` file is a Python script: it builds a :class:`ParameterGenerator`, adds parameters,
constants, enums and groups, and ends with ``exit(gen.generate(PACKAGE, node, "Name"))``.
catkin runs it at build time to write ``NameConfig.py``; minros runs it when the module is
imported (or when ``catkin_make`` checks the package) and builds the module in memory, with
the same contents as dynamic_reconfigure 1.7's generator writes: ``config_description``
(the group tree), ``min``, ``max``, ``defaults``, ``level``, ``type``, ``all_level``, ``inf``
and one ``Name_<constant>`` per constant.

The one difference: each parameter's and group's ``srcline``/``srcfile`` name the line of the
``.cfg`` that declared it; ROS records a line of its own generator for some of them. Those
fields are not part of the ROS messages.
"""

from __future__ import annotations

import builtins
import copy
import inspect
import os
import re
import sys
import threading
from pathlib import Path
from typing import Any, Callable, Dict, List, Optional

str_t = "str"
bool_t = "bool"
int_t = "int"
double_t = "double"

_PY_TYPES = {"str": str, "int": int, "double": float, "bool": bool}
_C_TYPES = {"str": "std::string", "int": "int", "double": "double", "bool": "bool"}
_C_CONST_TYPES = {"str": "const char * const", "int": "const int", "double": "const double",
                  "bool": "const bool"}
_MIN = {"int": -0x80000000, "double": -float("inf"), "str": "", "bool": False}
_MAX = {"int": 0x7FFFFFFF, "double": float("inf"), "str": "", "bool": True}
_DEFAULT = {"int": 0, "double": 0, "str": "", "bool": False}
_NAME_RE = re.compile(r"^[a-zA-Z][a-zA-Z0-9_]*$")

_USAGE_EXIT = """\
ahhhh! Unexpected command line syntax!

Are you trying to call a dynamic_reconfigure configuration generation script
directly? When you are using dynamic_reconfigure with python, you don't ever
need to invoke the configuration generator script yourself; it loads
automatically. If you are using dynamic_reconfigure from C++, you need to
add a call to generate_dynamic_reconfigure_options() in your CMakeLists.txt

For an example, see http://wiki.ros.org/dynamic_reconfigure/Tutorials

Have a nice day
"""


class CfgError(Exception):
    """A ``.cfg`` script failed; the text is one line naming the file and line."""


def _caller(depth: int = 2) -> tuple:
    """(line, file name) of the code that called the public method ``depth`` frames up."""
    frame = inspect.currentframe()
    for _ in range(depth):
        frame = frame.f_back if frame is not None else None
    if frame is None:
        return 0, ""
    return frame.f_lineno, os.path.basename(frame.f_code.co_filename)


def check_description(description: str) -> None:
    if '"' in description or "'" in description:
        raise Exception(f"quotes not allowed in description string `{description}`")


def check_name(name: str) -> None:
    if not isinstance(name, str) or not _NAME_RE.match(name):
        raise Exception(f"The name of field '{name}' does not follow the ROS naming conventions, "
                        "see http://wiki.ros.org/ROS/Patterns/Conventions")


def _check_type(entry: Dict[str, Any], field: str) -> None:
    """Coerce ``entry[field]`` to the entry's type (an int is a fine double), or refuse it."""
    kind, value = entry["type"], entry[field]
    pytype = _PY_TYPES[kind]
    if type(value) is not pytype and not (pytype is float and type(value) is int):
        raise TypeError(f"'{entry['name']}' has type {kind}, but {field} is {value!r}")
    entry[field] = pytype(value)


def _fill_type(entry: Dict[str, Any]) -> None:
    kind = entry["type"]
    if kind not in _PY_TYPES:
        raise TypeError(f"'{entry['name']}' has unknown type {kind!r}: use int_t, double_t, "
                        "str_t or bool_t")
    entry["ctype"] = _C_TYPES[kind]
    entry["cconsttype"] = _C_CONST_TYPES[kind]


class ParameterGenerator:
    """What a ``.cfg`` script builds: parameters in a tree of groups, and constants."""

    class Group:
        """A group of parameters (the generator's root group is "Default", id 0)."""

        def __init__(self, gen: ParameterGenerator, name: str, type: str, state: bool, id: int,
                     parent: int, srcline: int = 0, srcfile: str = "") -> None:
            self.name = name.replace(" ", "_")
            self.type = type
            self.groups: List[ParameterGenerator.Group] = []
            self.parameters: List[Dict[str, Any]] = []
            self.gen = gen
            self.id = id
            self.parent = parent
            self.state = state
            self.srcline = srcline
            self.srcfile = srcfile
            gen._groups[id] = self

        def get_group(self, id: int) -> ParameterGenerator.Group:
            return self.gen._groups[id]

        def add_group(self, name: str, type: str = "", state: bool = True) -> ParameterGenerator.Group:
            line, file = _caller()
            return self.gen._new_group(self, name, type, state, line, file)

        def add(self, name: str, paramtype: str, level: int, description: str, default: Any = None,
                min: Any = None, max: Any = None, edit_method: str = "") -> None:
            line, file = _caller()
            self._add(name, paramtype, level, description, default, min, max, edit_method, line, file)

        def _add(self, name: str, paramtype: str, level: int, description: str, default: Any,
                 min: Any, max: Any, edit_method: str, line: int, file: str) -> None:
            param = {"name": name, "type": paramtype, "default": default, "level": level,
                     "description": description, "min": min, "max": max, "srcline": line,
                     "srcfile": file, "edit_method": edit_method}
            if paramtype in (str_t, bool_t) and (max is not None or min is not None):
                raise Exception(f"Max or min specified for {name}, which is of '{paramtype}' type")
            check_name(name)
            _fill_type(param)
            for field, fallback in (("default", _DEFAULT), ("max", _MAX), ("min", _MIN)):
                if param[field] is None:
                    param[field] = fallback[paramtype]
                else:
                    _check_type(param, field)
            self.parameters.append(param)

        def get_parameters(self) -> List[Dict[str, Any]]:
            """This group's parameters, then its subgroups', depth first."""
            params = list(self.parameters)
            for group in self.groups:
                params.extend(group.get_parameters())
            return params

        def get_parents(self) -> List[str]:
            """Names from the root group down to this one."""
            if self.id == 0:
                return [self.name]
            return self.get_group(self.parent).get_parents() + [self.name]

        def get_field(self) -> str:
            return "::".join(x.lower() if x == self.name else x.upper() for x in self.get_parents())

        def get_class(self, parent: bool = False) -> str:
            names = [x.upper() for x in self.get_parents()]
            return "::".join(names[:-1] if parent else names)

        def to_dict(self) -> Dict[str, Any]:
            """The group as the generated module's ``config_description`` holds it."""
            return {
                "name": self.name, "type": self.type, "state": self.state,
                "cstate": "true" if self.state else "false", "id": self.id, "parent": self.parent,
                "parameters": self.parameters, "groups": [g.to_dict() for g in self.groups],
                "srcline": self.srcline, "srcfile": self.srcfile, "class": self.get_class(),
                "parentclass": self.get_class(parent=True),
                "parentname": self.get_group(self.parent).name, "field": self.get_field(),
                "upper": self.name.upper(), "lower": "groups" if self.id == 0 else self.name.lower(),
            }

    def __init__(self) -> None:
        if _capture() is None:
            # run as a plain script: catkin would pass four folders; minros needs none
            if len(sys.argv) < 5:
                raise SystemExit(_USAGE_EXIT)
        line, file = _caller()
        self._groups: Dict[int, ParameterGenerator.Group] = {}
        self._next_id = 1
        self.group = self.Group(self, "Default", "", True, 0, 0, line, file)
        self.constants: List[Dict[str, Any]] = []
        self.pkgname = self.name = self.nodename = self.msgname = ""

    def _new_group(self, parent: ParameterGenerator.Group, name: str, type: str, state: bool,
                   line: int, file: str) -> ParameterGenerator.Group:
        group = self.Group(self, name, type, state, self._next_id, parent.id, line, file)
        self._next_id += 1
        parent.groups.append(group)
        return group

    def const(self, name: str, type: str, value: Any, descr: str) -> Dict[str, Any]:
        line, file = _caller()
        const = {"name": name, "type": type, "value": value, "srcline": line, "srcfile": file,
                 "description": descr}
        check_description(descr)
        _fill_type(const)
        _check_type(const, "value")
        self.constants.append(const)
        return const

    def enum(self, constants: List[Dict[str, Any]], description: str) -> str:
        """An ``edit_method`` offering the constants (the text ROS sends to GUIs)."""
        if len({c["type"] for c in constants}) != 1:
            raise Exception("Inconsistent types in enum!")
        check_description(description)
        return repr({"enum": constants, "enum_description": description})

    def add(self, name: str, paramtype: str, level: int, description: str, default: Any = None,
            min: Any = None, max: Any = None, edit_method: str = "") -> None:
        line, file = _caller()
        self.group._add(name, paramtype, level, description, default, min, max, edit_method,
                        line, file)

    def add_group(self, name: str, type: str = "", state: bool = True) -> ParameterGenerator.Group:
        line, file = _caller()
        return self._new_group(self.group, name, type, state, line, file)

    def generate(self, pkgname: str, nodename: str, name: str) -> None:
        """Record the configuration named ``name`` (the module becomes ``<name>Config``)."""
        self.pkgname, self.nodename, self.name = pkgname, nodename, name
        self.msgname = name + "Config"
        capture = _capture()
        if capture is None:
            raise SystemExit(_USAGE_EXIT)
        capture.append(self)
        out = getattr(_state, "out", None)
        if out is not None:
            out(f"Generating reconfiguration files for {name} in {pkgname}")


_state = threading.local()


def _capture() -> Optional[list]:
    return getattr(_state, "capture", None)


# ---------------------------------------------------------------------------------------------
# running a .cfg

def run_cfg(path: Path, out: Optional[Callable[[str], None]] = None) -> ParameterGenerator:
    """Run the ``.cfg`` script at ``path``; the generator it called ``generate`` on.

    ``out`` gets the line catkin prints for each generated configuration. Raises
    :class:`CfgError` (one line: ``file:line: what``) if the script fails.
    """
    path = Path(path)
    try:
        source = path.read_text(encoding="utf-8")
    except (OSError, UnicodeDecodeError) as exc:
        raise CfgError(f"{path}: cannot read: {exc}") from None
    try:
        code = compile(source, str(path), "exec")
    except SyntaxError as exc:
        raise CfgError(f"{path}:{exc.lineno}: SyntaxError: {exc.msg}") from None
    namespace: Dict[str, Any] = {"__name__": "__main__", "__file__": str(path),
                                 "__builtins__": builtins}
    previous = (_capture(), getattr(_state, "out", None))
    _state.capture, _state.out = [], out
    try:
        try:
            exec(code, namespace)
        except SystemExit as exc:
            if exc.code not in (None, 0):
                raise CfgError(f"{path}: the script exited with status {exc.code!r} before "
                               "generating its configuration") from None
        except Exception as exc:  # noqa: BLE001 - any error of the user's script, located
            raise CfgError(f"{path}:{_script_line(exc, str(path))}: {type(exc).__name__}: "
                           f"{_one_line(exc)}") from None
        generated = _state.capture
    finally:
        _state.capture, _state.out = previous
    if not generated:
        raise CfgError(f"{path}: the script never called gen.generate(PACKAGE, node_name, "
                       f"\"{path.stem}\")")
    return generated[-1]


def _script_line(exc: BaseException, filename: str) -> int:
    """The line of ``filename`` deepest in ``exc``'s traceback (where the script went wrong)."""
    line = 0
    tb = exc.__traceback__
    while tb is not None:
        if tb.tb_frame.f_code.co_filename == filename:
            line = tb.tb_lineno
        tb = tb.tb_next
    return line


def _one_line(exc: BaseException) -> str:
    text = str(exc) if not isinstance(exc, KeyError) else repr(exc.args[0]) if exc.args else ""
    return " ".join(text.split()) or type(exc).__name__


def module_namespace(gen: ParameterGenerator) -> Dict[str, Any]:
    """The globals of ``<name>Config``, as dynamic_reconfigure's generator writes them."""
    from .encoding import extract_params

    description = copy.deepcopy(gen.group.to_dict())
    namespace: Dict[str, Any] = {
        "extract_params": extract_params, "inf": float("inf"), "config_description": description,
        "min": {}, "max": {}, "defaults": {}, "level": {}, "type": {}, "all_level": 0,
    }
    all_level = 0
    for param in extract_params(description):
        name = param["name"]
        namespace["min"][name] = param["min"]
        namespace["max"][name] = param["max"]
        namespace["defaults"][name] = param["default"]
        namespace["level"][name] = param["level"]
        namespace["type"][name] = param["type"]
        all_level |= param["level"]
    namespace["all_level"] = all_level
    for const in gen.constants:
        namespace[f"{gen.name}_{const['name']}"] = const["value"]
    return namespace


def cfg_files(package_dir: Path) -> List[Path]:
    """The ``cfg/*.cfg`` scripts of a package, sorted."""
    try:
        return sorted(p for p in (Path(package_dir) / "cfg").iterdir()
                      if p.suffix == ".cfg" and p.is_file())
    except OSError:
        return []


def find_cfg(package_dir: Path, module_name: str) -> Optional[Path]:
    """The ``.cfg`` of ``package_dir`` that generates ``<module_name>`` (``NameConfig``).

    ``cfg/Name.cfg`` by convention; otherwise the script whose ``generate`` names it.
    """
    if not module_name.endswith("Config") or module_name == "Config":
        return None
    stem = module_name[:-len("Config")]
    direct = Path(package_dir) / "cfg" / f"{stem}.cfg"
    if direct.is_file():
        return direct
    for path in cfg_files(package_dir):
        try:
            if run_cfg(path).name == stem:
                return path
        except CfgError:
            continue
    return None
