"""roslib.msgs: message specs the rosbuild way, and the process's table of registered types.

Differences from genmsg's model, kept because callers see them: ``Header`` stays ``Header``
in a spec's types (it is registered under ``Header``, ``std_msgs/Header`` and
``roslib/Header``); a spec's equality ignores its names; every error is MsgSpecException.
"""

from __future__ import annotations

import os
import sys
from io import StringIO
from typing import Any, Dict, List, Optional, Tuple

from minros import names as _names
from minros import packages as _packages

from .. import loader as _loader
from .. import spec as _spec

VERBOSE = False

EXT = ".msg"
SEP = "/"
CONSTCHAR = "="
COMMENTCHAR = "#"
HEADER = "Header"
TIME = "time"
DURATION = "duration"
TIME_MSG = "uint32 secs\nuint32 nsecs"
DURATION_MSG = "int32 secs\nint32 nsecs"
PRIMITIVE_TYPES = ["int8", "uint8", "int16", "uint16", "int32", "uint32", "int64", "uint64",
                   "float32", "float64", "string", "bool", "char", "byte"]
BUILTIN_TYPES = PRIMITIVE_TYPES + [TIME, DURATION]
RESERVED_TYPES = BUILTIN_TYPES + [HEADER]


def is_verbose() -> bool:
    return VERBOSE


def set_verbose(v: bool) -> None:
    global VERBOSE
    VERBOSE = v


class MsgSpecException(Exception):
    """A message definition or type name is not valid."""


def base_msg_type(type_: Optional[str]) -> Optional[str]:
    """``'std_msgs/String[10]'`` -> ``'std_msgs/String'``."""
    return _loader.bare_msg_type(type_)


def resolve_type(type_: str, package_context: str) -> str:
    """``String`` in ``std_msgs`` -> ``std_msgs/String``; builtins as they are; ``Header`` ->
    ``std_msgs/Header``."""
    return _loader.resolve_type(type_, package_context)


def parse_type(type_: Optional[str]) -> Tuple[str, bool, Optional[int]]:
    """``(base type, is array, length or None)``; MsgSpecException when unparsable."""
    try:
        return _loader.parse_type(type_ or "")
    except ValueError as exc:
        raise MsgSpecException(str(exc)) from None


def is_valid_msg_type(x: Optional[str]) -> bool:
    return bool(x) and _loader.is_valid_msg_type(x)  # type: ignore[arg-type]


def is_valid_constant_type(x: str) -> bool:
    return x in PRIMITIVE_TYPES


def is_valid_msg_field_name(x: str) -> bool:
    return _loader.is_valid_msg_field_name(x)


def is_header_type(type_: str) -> bool:
    return type_ in (HEADER, "std_msgs/Header", "roslib/Header")


def is_builtin(msg_type_name: str) -> bool:
    return msg_type_name in BUILTIN_TYPES


class Constant:
    """A constant declaration: type, name (stripped), value and its text."""

    __slots__ = ["type", "name", "val", "val_text"]

    def __init__(self, type_: str, name: str, val: Any, val_text: str) -> None:
        if type_ is None or name is None or val is None or val_text is None:
            raise ValueError("Constant must have non-None parameters")
        self.type = type_
        self.name = name.strip()
        self.val = val
        self.val_text = val_text

    def __eq__(self, other: object) -> bool:
        return isinstance(other, Constant) and \
            (self.type, self.name, self.val) == (other.type, other.name, other.val)

    __hash__ = None  # type: ignore[assignment]

    def __repr__(self) -> str:
        return f"{self.type} {self.name}={self.val}"

    __str__ = __repr__


class Field:
    """One field: name, type, and the type's parts."""

    def __init__(self, name: str, type: str) -> None:  # noqa: A002 - roslib's keyword
        self.name = name
        self.type = type
        self.base_type, self.is_array, self.array_len = parse_type(type)
        self.is_header = is_header_type(self.base_type)
        self.is_builtin = is_builtin(self.base_type)

    def __repr__(self) -> str:
        return f"[{self.name}, {self.type}, {self.base_type}, {self.is_array}, {self.array_len}]"


class MsgSpec:
    """A message's field types and names (parallel lists), constants and text."""

    def __init__(self, types: List[str], names: List[str], constants: List[Any], text: str,
                 full_name: str = "", short_name: str = "", package: str = "") -> None:
        if len(set(names)) != len(names):
            raise MsgSpecException(f"Duplicate field names in message: {names}")
        if len(types) != len(names):
            raise MsgSpecException(f"len({types}) != len({names})")
        self.types = types
        self.names = names
        self.constants = constants
        self.header_present = bool(types) and is_header_type(types[0]) and names[0] == "header"
        self.text = text
        self.full_name = full_name
        self.short_name = short_name
        self.package = package
        self._parsed_fields = [Field(n, t) for n, t in zip(names, types)]

    def fields(self) -> List[Tuple[str, str]]:
        return list(zip(self.types, self.names))

    def parsed_fields(self) -> List[Field]:
        return self._parsed_fields

    def has_header(self) -> bool:
        return self.header_present

    def __eq__(self, other: object) -> bool:
        if not other or not isinstance(other, MsgSpec):
            return False
        return (self.types, self.names, self.constants, self.text) == \
            (other.types, other.names, other.constants, other.text)

    def __ne__(self, other: object) -> bool:
        return not self == other

    __hash__ = None  # type: ignore[assignment]

    def __repr__(self) -> str:
        if self.constants:
            return f"MsgSpec[{self.constants!r}, {self.types!r}, {self.names!r}]"
        return f"MsgSpec[{self.types!r}, {self.names!r}]"

    def __str__(self) -> str:
        return _strify_spec(self)


def _strify_spec(spec: MsgSpec, buff: Optional[StringIO] = None, indent: str = "") -> str:
    """The spec's declarations, embedded registered types indented below their field."""
    buff = StringIO() if buff is None else buff
    for c in spec.constants:
        buff.write(f"{indent}{c.type} {c.name}={c.val_text}\n")
    for type_, name in zip(spec.types, spec.names):
        buff.write(f"{indent}{type_} {name}\n")
        base = base_msg_type(type_) or type_
        if base not in BUILTIN_TYPES:
            _strify_spec(get_registered(base), buff, indent + "  ")
    return buff.getvalue()


# ---------------------------------------------------------------------------------------------
# parsing

def _convert_val(type_: str, val: str) -> Any:
    """A constant's value text as Python: ValueError when it is no value of the type,
    MsgSpecException when out of range or the type has no constants."""
    if type_ not in PRIMITIVE_TYPES:
        raise MsgSpecException(f"invalid constant type: [{type_}]")
    try:
        return _spec._convert_constant(type_, val)
    except _spec.ConstantRangeError as exc:
        raise MsgSpecException(str(exc)) from None


def load_from_string(text: str, package_context: str = "", full_name: str = "",
                     short_name: str = "") -> MsgSpec:
    """Parse ``.msg`` text; a bare message type is put in ``package_context`` (when given)."""
    types: List[str] = []
    field_names: List[str] = []
    constants: List[Constant] = []
    for orig_line in text.split("\n"):
        clean = _spec._strip_comment(orig_line)
        if not clean:
            continue
        type_ = clean.split()[0]
        if not is_valid_msg_type(type_):
            raise MsgSpecException(f"{type_} is not a legal message type")
        if CONSTCHAR in clean:
            if not is_valid_constant_type(type_):
                raise MsgSpecException(f"{type_} is not a legal constant type")
            try:
                parsed = _spec._parse_constant(orig_line, clean)
            except ValueError as exc:
                raise MsgSpecException(f"Invalid declaration: {exc}") from None
            constants.append(Constant(parsed.type, parsed.name, parsed.value, parsed.val_text))
            continue
        words = clean.split()
        if len(words) != 2:
            raise MsgSpecException(f"Invalid declaration: {clean}")
        name = words[1]
        if not is_valid_msg_field_name(name):
            raise MsgSpecException(f"{name} is not a legal message field name")
        if package_context and SEP not in type_ and base_msg_type(type_) not in RESERVED_TYPES:
            type_ = f"{package_context}/{type_}"
        types.append(type_)
        field_names.append(name)
    return MsgSpec(types, field_names, constants, text, full_name, short_name, package_context)


def _type_name(file_path: str, ext: str, package_context: str) -> Tuple[str, str, str]:
    """(type name, short name, package) of a definition file in ``package_context``."""
    short = os.path.basename(file_path)[:-len(ext)]
    package_context = package_context.rstrip(SEP) if package_context else package_context
    type_ = f"{package_context}{SEP}{short}" if package_context else short
    return type_, short, package_context


def load_from_file(file_path: str, package_context: str = "") -> Tuple[str, MsgSpec]:
    """``(type name, spec)`` of a ``.msg`` file (not registered)."""
    if VERBOSE:
        where = f" into package [{package_context}]" if package_context else ""
        print("Load spec from", file_path + where)
    type_, short, package_context = _type_name(file_path, EXT, package_context)
    if not _names.is_legal_resource_name(type_):
        raise MsgSpecException(f"{file_path}: [{type_}] is not a legal type name")
    with open(file_path) as f:
        text = f.read()
    try:
        return type_, load_from_string(text, package_context, type_, short)
    except MsgSpecException as exc:
        raise MsgSpecException(f"{os.path.basename(file_path)}: {exc}") from None


def load_by_type(msgtype: str, package_context: str = "") -> Tuple[str, MsgSpec]:
    """Find ``pkg/Type`` (or ``Type`` in ``package_context``) and load it."""
    package, base = _names.package_resource_name(msgtype)
    package = package or package_context
    try:
        path = msg_file(package, base)
    except _packages.InvalidROSPkgException:
        raise MsgSpecException(f"Cannot locate message type [{msgtype}], package [{package}] "
                               "does not exist") from None
    return load_from_file(path, package)


# ---------------------------------------------------------------------------------------------
# packages

def _msg_filter(f: str) -> bool:
    return os.path.isfile(f) and f.endswith(EXT)


def list_msg_types(package: str, include_depends: bool) -> List[str]:
    """The message types of ``package`` (and its dependencies', as ``pkg/Type``)."""
    found = _packages.list_package_resources(package, include_depends, "msg", _msg_filter)
    return [x[:-len(EXT)] for x in found]


def msg_file(package: str, type_: str) -> str:
    """The path of ``package``'s ``type_.msg``, whether or not it exists."""
    return _packages.resource_file(package, "msg", type_ + EXT)


def get_pkg_msg_specs(package: str) -> Tuple[List[Tuple[str, MsgSpec]], List[str]]:
    """The package's ``(type, spec)`` pairs, and the types that failed to load (printed)."""
    _init()
    specs, failures = [], []
    for t in list_msg_types(package, False):
        try:
            specs.append(load_from_file(msg_file(package, t), package))
        except Exception as exc:
            failures.append(t)
            print(f"ERROR: unable to load {t}, {exc}")
    return specs, failures


def load_package_dependencies(package: str, load_recursive: bool = False) -> None:
    """Register the messages of the packages ``package`` depends on (its manifest's, or all
    with ``load_recursive``)."""
    _init()
    if VERBOSE:
        print("Load dependencies for package", package)
    if load_recursive:
        depends = _packages.rospack().get_depends(package, implicit=True)
    else:
        path = _packages.manifest_file(package, True)
        assert path is not None  # required: a package without one raised
        manifest = _packages.parse_manifest_file(path)
        depends = [d.package for d in manifest.depends]
    loaded = []
    for dep in depends:
        if dep in _loaded_packages or dep == package:
            continue
        _loaded_packages.append(dep)
        loaded += get_pkg_msg_specs(dep)[0]
    for key, spec in loaded:
        register(key, spec)


def load_package(package: str) -> None:
    """Register every message of ``package`` under its short and full names (once)."""
    _init()
    if package in _loaded_packages:
        if VERBOSE:
            print(f"Package {package} is already loaded")
        return
    _loaded_packages.append(package)
    for key, spec in get_pkg_msg_specs(package)[0]:
        register(key, spec)
        register(f"{package}/{key}", spec)


# ---------------------------------------------------------------------------------------------
# the table of registered types

EXTENDED_BUILTINS = {TIME: load_from_string(TIME_MSG), DURATION: load_from_string(DURATION_MSG)}
REGISTERED_TYPES: Dict[str, MsgSpec] = {}
_loaded_packages: List[str] = []
_initialized = False


def _init() -> Optional[bool]:
    """Register Header (under its three names), time and duration, once."""
    global _initialized
    if _initialized:
        return None
    std_msgs_dir = _packages.get_pkg_dir("std_msgs", required=False)
    if std_msgs_dir is None:
        raise MsgSpecException(f"Unable to locate roslib: {EXT} files cannot be loaded")
    header = os.path.join(std_msgs_dir, "msg", HEADER + EXT)
    if not os.path.isfile(header):
        sys.stderr.write(f"ERROR: cannot locate {HEADER}{EXT}. Expected to find it at '{header}'\n")
        return False
    _, spec = load_from_file(header, "")
    for name in (HEADER, "std_msgs/" + HEADER, "roslib/" + HEADER):
        register(name, spec)
    for name, builtin in EXTENDED_BUILTINS.items():
        register(name, builtin)
    _initialized = True
    return None


def reinit() -> None:
    """Forget every registered type and loaded package, then register the builtins again."""
    global _initialized
    _initialized = False
    del _loaded_packages[:]
    REGISTERED_TYPES.clear()
    _init()


def is_registered(msg_type_name: str) -> bool:
    return msg_type_name in REGISTERED_TYPES


def get_registered(msg_type_name: str, default_package: Optional[str] = None) -> MsgSpec:
    """The registered spec (a bare name also looked up in ``default_package``); KeyError."""
    if msg_type_name in REGISTERED_TYPES:
        return REGISTERED_TYPES[msg_type_name]
    if default_package:
        package, _ = _names.package_resource_name(msg_type_name)
        if not package:
            return REGISTERED_TYPES[f"{default_package}/{msg_type_name}"]
    raise KeyError(msg_type_name)


def register(msg_type_name: str, msg_spec: MsgSpec) -> None:
    if VERBOSE:
        print(f"Register msg {msg_type_name}")
    REGISTERED_TYPES[msg_type_name] = msg_spec
