"""genmsg's Python API over minros's parser: MsgContext, search paths, the loaders, md5 sums
and full texts of specs.

Tools written for genmsg (generators, rosmsg-like introspection, bridges) load definitions
into a :class:`MsgContext` from a search path ``{package: [folder, ...]}`` and ask
:func:`compute_md5` / :func:`compute_full_text` for the two texts. The parsing, the md5 text
and the full text are minros's (:mod:`minros.msgs.spec`, checked against Debian's genmsg for
every bundled type); this module keeps genmsg's data model on top: specs with ``types``,
``names`` and ``fields()``, a context that holds specs, files and first-order dependencies,
and genmsg's exceptions.
"""

from __future__ import annotations

import os
from typing import Any, Dict, List, Mapping, Sequence, Tuple, overload

from minros.names import package_resource_name

from . import spec as _spec
from .spec import (
    BUILTIN_TYPES,
    HEADER,
    HEADER_FULL_NAME,
    PRIMITIVE_TYPES,
    Constant,
    Field,
    MsgSpecError,
)

SEP = "/"
MSG_DIR = "msg"
SRV_DIR = "srv"
EXT_MSG = ".msg"
EXT_SRV = ".srv"
CONSTCHAR = "="
COMMENTCHAR = "#"
IODELIM = "---"
TIME = "time"
DURATION = "duration"
TIME_MSG = "uint32 secs\nuint32 nsecs"
DURATION_MSG = "int32 secs\nint32 nsecs"

__all__ = [
    "MsgSpec", "SrvSpec", "Field", "Constant", "MsgContext", "MsgNotFound", "InvalidMsgSpec",
    "MsgGenerationException", "load_msg_by_type", "load_srv_by_type", "load_msg_from_string",
    "load_msg_from_file", "load_srv_from_string", "load_srv_from_file", "load_depends",
    "load_msg_depends", "get_msg_file", "get_srv_file", "compute_md5", "compute_md5_text",
    "compute_full_text", "compute_full_type_name", "bare_msg_type", "resolve_type",
    "parse_type", "is_valid_msg_type", "is_valid_constant_type", "is_valid_msg_field_name",
    "is_header_type", "is_builtin", "HEADER", "HEADER_FULL_NAME", "TIME", "DURATION",
    "PRIMITIVE_TYPES", "BUILTIN_TYPES",
]


class InvalidMsgSpec(Exception):
    """A definition is malformed (genmsg.InvalidMsgSpec); the text names the file and line."""


class MsgGenerationException(Exception):
    """Code generation failed (genmsg.MsgGenerationException)."""


class MsgNotFound(Exception):
    """A type's file is not on the search path (genmsg.msg_loader.MsgNotFound)."""

    def __init__(self, message: str, base_type: str | None = None, package: str | None = None,
                 search_path: Any = None) -> None:
        super().__init__(message)
        self.base_type = base_type
        self.package = package
        self.search_path = search_path


# ---------------------------------------------------------------------------------------------
# type names (genmsg.msgs)

@overload
def bare_msg_type(msg_type: str) -> str: ...
@overload
def bare_msg_type(msg_type: None) -> None: ...


def bare_msg_type(msg_type: str | None) -> str | None:
    """``'std_msgs/String[]'`` -> ``'std_msgs/String'``."""
    if msg_type is None:
        return None
    return msg_type[:msg_type.find("[")] if "[" in msg_type else msg_type


def resolve_type(msg_type: str, package_context: str) -> str:
    """A field type as it is stored: builtins unchanged, ``Header`` -> ``std_msgs/Header``,
    an unqualified name in ``package_context``."""
    bare = bare_msg_type(msg_type)
    if bare in BUILTIN_TYPES:
        return msg_type
    if bare == HEADER:
        return HEADER_FULL_NAME
    if SEP in msg_type:
        return msg_type
    return f"{package_context}{SEP}{msg_type}"


def parse_type(msg_type: str) -> Tuple[str, bool, int | None]:
    """``(base type, is array, length or None)``; ``ValueError`` for an unparsable type."""
    if not msg_type:
        raise ValueError("Invalid empty type")
    if "[" not in msg_type:
        return msg_type, False, None
    splits = msg_type.split("[")
    if len(splits) > 2:
        raise ValueError(f"Currently only support 1-dimensional array types: {msg_type}")
    if msg_type.endswith("[]"):
        return msg_type[:-2], True, None
    try:
        return splits[0], True, int(splits[1][:-1])
    except ValueError:
        raise ValueError(f"Invalid array dimension: [{splits[1][:-1]}]") from None


def is_valid_msg_type(x: str) -> bool:
    """A legal field type: a resource name followed by ``[]``/``[N]`` groups."""
    from minros.names import is_legal_resource_name

    if not x or len(x) != len(x.strip()):
        return False
    base = bare_msg_type(x)
    if not is_legal_resource_name(base):
        return False
    is_open = False
    for c in x[len(base):]:
        if not is_open:
            if c != "[":
                return False
            is_open = True
        elif c == "]":
            is_open = False
        elif not c.isdigit():
            return False
    return not is_open


def is_valid_constant_type(x: str) -> bool:
    return x in PRIMITIVE_TYPES


def is_valid_msg_field_name(x: str) -> bool:
    from minros.names import is_legal_resource_base_name

    return is_legal_resource_base_name(x)


def is_header_type(msg_type: str) -> bool:
    return msg_type in (HEADER, HEADER_FULL_NAME, "roslib/Header")


def is_builtin(msg_type_name: str) -> bool:
    return msg_type_name in BUILTIN_TYPES


# ---------------------------------------------------------------------------------------------
# specs with genmsg's shape

class MsgSpec:
    """A message definition as genmsg exposes it: parallel ``types`` and ``names``, constants,
    the text, and the names; the parsed minros spec it wraps is :attr:`spec`."""

    def __init__(self, types: List[str], names: List[str], constants: List[Constant], text: str,
                 full_name: str, package: str = "", short_name: str = "") -> None:
        alt_package, alt_short = package_resource_name(full_name)
        if len(set(names)) != len(names):
            raise InvalidMsgSpec(f"Duplicate field names in message: {names}")
        if len(types) != len(names):
            raise InvalidMsgSpec(f"len({types}) != len({names})")
        try:
            fields = [Field(name, type_) for name, type_ in zip(names, types)]
        except ValueError as exc:
            raise InvalidMsgSpec(f"invalid field: {exc}") from None
        self.types = list(types)
        self.names = list(names)
        self.constants = list(constants)
        self.text = text
        self.full_name = full_name
        self.package = package or alt_package
        self.short_name = short_name or alt_short
        self.header_present = bool(types) and types[0] == HEADER_FULL_NAME and names[0] == "header"
        self.spec = _spec.MsgSpec(full_name, fields, self.constants, text)

    @classmethod
    def _from_parsed(cls, parsed: _spec.MsgSpec) -> MsgSpec:
        return cls([f.type for f in parsed.fields], [f.name for f in parsed.fields],
                   parsed.constants, parsed.text, parsed.full_name)

    def fields(self) -> List[Tuple[str, str]]:
        """``[(type, name), ...]``."""
        return list(zip(self.types, self.names))

    def parsed_fields(self) -> List[Field]:
        return list(self.spec.fields)

    def has_header(self) -> bool:
        return self.header_present

    def __eq__(self, other: object) -> bool:
        if not isinstance(other, MsgSpec):
            return False
        return (self.types, self.names, self.constants, self.text, self.full_name,
                self.short_name, self.package) == \
            (other.types, other.names, other.constants, other.text, other.full_name,
             other.short_name, other.package)

    def __ne__(self, other: object) -> bool:
        return not self == other

    __hash__ = None  # type: ignore[assignment]

    def __repr__(self) -> str:
        if self.constants:
            return f"MsgSpec[{self.constants!r}, {self.types!r}, {self.names!r}]"
        return f"MsgSpec[{self.types!r}, {self.names!r}]"

    def __str__(self) -> str:
        return self.text


class SrvSpec:
    """A service definition: its request and response :class:`MsgSpec`."""

    def __init__(self, request: MsgSpec, response: MsgSpec, text: str, full_name: str = "",
                 short_name: str = "", package: str = "") -> None:
        alt_package, alt_short = package_resource_name(full_name)
        self.request = request
        self.response = response
        self.text = text
        self.full_name = full_name
        self.short_name = short_name or alt_short
        self.package = package or alt_package

    def __eq__(self, other: object) -> bool:
        if not isinstance(other, SrvSpec):
            return False
        return (self.request, self.response, self.text, self.full_name, self.short_name,
                self.package) == (other.request, other.response, other.text, other.full_name,
                                  other.short_name, other.package)

    def __ne__(self, other: object) -> bool:
        return not self == other

    __hash__ = None  # type: ignore[assignment]

    def __repr__(self) -> str:
        return f"SrvSpec[{self.request!r}, {self.response!r}]"


class MsgContext:
    """The specs loaded so far, the files they came from and their first-order dependencies."""

    def __init__(self) -> None:
        self._registered_packages: Dict[str, Dict[str, MsgSpec]] = {}
        self._files: Dict[str, str] = {}
        self._dependencies: Dict[str, List[str]] = {}

    @staticmethod
    def create_default() -> MsgContext:
        """A context with ``time`` and ``duration`` registered, as generators start from."""
        context = MsgContext()
        load_msg_from_string(context, TIME_MSG, TIME)
        load_msg_from_string(context, DURATION_MSG, DURATION)
        return context

    def set_file(self, full_msg_type: str, file_path: str) -> None:
        self._files[full_msg_type] = file_path

    def get_file(self, full_msg_type: str) -> str | None:
        return self._files.get(full_msg_type)

    def set_depends(self, full_msg_type: str, dependencies: List[str]) -> None:
        self._dependencies[full_msg_type] = dependencies

    def get_depends(self, full_msg_type: str) -> List[str] | None:
        return self._dependencies.get(full_msg_type)

    def get_all_depends(self, full_msg_type: str) -> List[str]:
        """Every dependency, depth first (``KeyError`` when one was never loaded)."""
        depends = self.get_depends(full_msg_type)
        if depends is None:
            raise KeyError(full_msg_type)
        out: List[str] = []
        for dep in depends:
            out.append(dep)
            out.extend(self.get_all_depends(dep))
        return out

    def register(self, full_msg_type: str, msgspec: MsgSpec) -> None:
        package, base_type = package_resource_name(bare_msg_type(full_msg_type))
        self._registered_packages.setdefault(package, {})[base_type] = msgspec

    def is_registered(self, full_msg_type: str) -> bool:
        package, base_type = package_resource_name(bare_msg_type(full_msg_type))
        return base_type in self._registered_packages.get(package, {})

    def get_registered(self, full_msg_type: str) -> MsgSpec:
        """The spec of a loaded type; ``KeyError`` when it was not loaded."""
        full_msg_type = bare_msg_type(full_msg_type)
        if not self.is_registered(full_msg_type):
            raise KeyError(full_msg_type)
        package, base_type = package_resource_name(full_msg_type)
        return self._registered_packages[package][base_type]

    def __str__(self) -> str:
        return str(self._registered_packages)


# ---------------------------------------------------------------------------------------------
# one line of a definition (genmsg's line parsers, which its tests and generators call)

def _strip_comments(line: str) -> str:
    return _spec._strip_comment(line)


def convert_constant_value(field_type: str, val: str) -> object:
    """A constant's value text as Python: ``ValueError`` when it is no value of the type,
    :class:`InvalidMsgSpec` when it is out of the type's range or the type has no constants."""
    if field_type not in PRIMITIVE_TYPES:
        raise InvalidMsgSpec(f"invalid constant type: [{field_type}]")
    try:
        return _spec._convert_constant(field_type, val)
    except _spec.ConstantRangeError as exc:
        raise InvalidMsgSpec(str(exc)) from None


def _load_constant_line(orig_line: str) -> Constant:
    """``'int8 X=1'`` -> ``Constant('int8', 'X', 1, '1')`` (:class:`InvalidMsgSpec` if bad)."""
    clean = _strip_comments(orig_line)
    if not clean:
        raise InvalidMsgSpec(f"Invalid constant declaration: {orig_line}")
    try:
        return _spec._parse_constant(orig_line, clean)
    except ValueError as exc:
        raise InvalidMsgSpec(str(exc)) from None


def _load_field_line(orig_line: str, package_context: str) -> Tuple[str, str]:
    """``'Header header'`` -> ``('std_msgs/Header', 'header')``; a bare message type is
    resolved in ``package_context`` when one is given (:class:`InvalidMsgSpec` if bad)."""
    try:
        return _spec._parse_field(_strip_comments(orig_line), package_context)
    except ValueError as exc:
        raise InvalidMsgSpec(str(exc)) from None


def includepath_to_dict(includepath: Sequence[str] | None) -> Dict[str, List[str]]:
    """``['pkg:/dir', ...]`` (generators' ``-I`` options) -> the search path ``{pkg: [dir]}``."""
    search_path: Dict[str, List[str]] = {}
    for entry in includepath or ():
        package, _, folder = entry.partition(":")
        if folder:
            search_path.setdefault(package, []).append(folder)
    return search_path


# ---------------------------------------------------------------------------------------------
# loading

def _check_search_path(search_path: Any) -> None:
    if not isinstance(search_path, Mapping):
        raise ValueError("search_path must be a dictionary of {namespace: dirpath}")


def get_msg_file(package: str, base_type: str, search_path: Mapping[str, Sequence[str]],
                 ext: str = EXT_MSG) -> str:
    """The file of ``package/base_type`` in ``search_path`` (``MsgNotFound`` when absent)."""
    _check_search_path(search_path)
    if package not in search_path:
        raise MsgNotFound(f"Cannot locate message [{base_type}]: unknown package [{package}] "
                          f"on search path [{search_path}]", base_type, package, search_path)
    for folder in search_path[package]:
        path = os.path.join(folder, f"{base_type}{ext}")
        if os.path.isfile(path):
            return path
    raise MsgNotFound(f"Cannot locate message [{base_type}] in package [{package}] with paths "
                      f"[{search_path[package]}]", base_type, package, search_path)


def get_srv_file(package: str, base_type: str, search_path: Mapping[str, Sequence[str]]) -> str:
    return get_msg_file(package, base_type, search_path, ext=EXT_SRV)


def _read(file_path: str) -> str:
    try:
        with open(file_path, encoding="utf-8") as f:
            return f.read()
    except (OSError, UnicodeDecodeError) as exc:
        raise InvalidMsgSpec(f"{file_path}: cannot read: {exc}") from None


def load_msg_from_string(msg_context: MsgContext, text: str, full_name: str) -> MsgSpec:
    """Parse ``text`` as message ``full_name``, register and return its spec."""
    try:
        parsed = _spec.parse_msg(text, full_name)
    except MsgSpecError as exc:
        raise InvalidMsgSpec(str(exc)) from None
    spec = MsgSpec._from_parsed(parsed)
    msg_context.register(full_name, spec)
    return spec


def load_msg_from_file(msg_context: MsgContext, file_path: str, full_name: str) -> MsgSpec:
    try:
        spec = load_msg_from_string(msg_context, _read(file_path), full_name)
    except InvalidMsgSpec as exc:
        raise InvalidMsgSpec(f"{full_name}: {exc}") from None
    msg_context.set_file(full_name, file_path)
    return spec


def load_srv_from_string(msg_context: MsgContext, text: str, full_name: str) -> SrvSpec:
    """Parse ``text`` as service ``full_name``; its request and response are registered."""
    try:
        parsed = _spec.parse_srv(text, full_name)
    except MsgSpecError as exc:
        raise InvalidMsgSpec(str(exc)) from None
    request = MsgSpec._from_parsed(parsed.request)
    response = MsgSpec._from_parsed(parsed.response)
    msg_context.register(request.full_name, request)
    msg_context.register(response.full_name, response)
    return SrvSpec(request, response, text, full_name)


def load_srv_from_file(msg_context: MsgContext, file_path: str, full_name: str) -> SrvSpec:
    spec = load_srv_from_string(msg_context, _read(file_path), full_name)
    msg_context.set_file(f"{full_name}Request", file_path)
    msg_context.set_file(f"{full_name}Response", file_path)
    return spec


def load_msg_by_type(msg_context: MsgContext, msg_type: str,
                     search_path: Mapping[str, Sequence[str]]) -> MsgSpec:
    """Find ``pkg/Type`` on ``search_path``, load and register it (``Header`` is std_msgs's)."""
    _check_search_path(search_path)
    if msg_type == HEADER:
        msg_type = HEADER_FULL_NAME
    package, base_type = package_resource_name(msg_type)
    path = get_msg_file(package, base_type, search_path)
    return load_msg_from_file(msg_context, path, msg_type)


def load_srv_by_type(msg_context: MsgContext, srv_type: str,
                     search_path: Mapping[str, Sequence[str]]) -> SrvSpec:
    _check_search_path(search_path)
    package, base_type = package_resource_name(srv_type)
    path = get_srv_file(package, base_type, search_path)
    return load_srv_from_file(msg_context, path, srv_type)


def load_msg_depends(msg_context: MsgContext, spec: MsgSpec,
                     search_path: Mapping[str, Sequence[str]]) -> List[str]:
    """Load every type ``spec`` embeds, recursively; returns (a copy of) its first-order
    dependencies, one per field as genmsg lists them."""
    package_context = spec.package
    depends: List[str] = []
    for field in spec.parsed_fields():
        if field.is_builtin:
            continue
        dep = resolve_type(field.base_type, package_context)
        if msg_context.is_registered(dep):
            dep_spec = msg_context.get_registered(dep)
        else:
            dep_spec = load_msg_by_type(msg_context, dep, search_path)
            msg_context.register(dep, dep_spec)
        depends.append(dep)
        if msg_context.get_depends(dep) is None:
            load_msg_depends(msg_context, dep_spec, search_path)
    msg_context.set_depends(spec.full_name, depends)
    return list(depends)


def load_depends(msg_context: MsgContext, spec: Any,
                 msg_search_path: Mapping[str, Sequence[str]]) -> List[str]:
    """:func:`load_msg_depends` for a message, or for both halves of a service."""
    if isinstance(spec, MsgSpec):
        return load_msg_depends(msg_context, spec, msg_search_path)
    if isinstance(spec, SrvSpec):
        depends = load_msg_depends(msg_context, spec.request, msg_search_path)
        depends += load_msg_depends(msg_context, spec.response, msg_search_path)
        return depends
    raise ValueError(f"spec does not appear to be a message or service: {spec!r}")


# ---------------------------------------------------------------------------------------------
# md5 sums and full texts (genmsg.gentools)

def _get_spec(msg_context: MsgContext, package_context: str) -> Any:
    def get(type_name: str) -> _spec.MsgSpec:
        try:
            return msg_context.get_registered(type_name).spec
        except KeyError:
            raise MsgGenerationException(
                f"Cannot compute the texts of {package_context}: type [{type_name}] is not "
                "loaded (load_depends first)") from None
    return get


def compute_md5_text(msg_context: MsgContext, spec: Any) -> str:
    """The text a message's (or service's: request then response) md5 sum is taken of."""
    if isinstance(spec, SrvSpec):
        return compute_md5_text(msg_context, spec.request) + compute_md5_text(msg_context, spec.response)
    get = _get_spec(msg_context, spec.full_name)

    def md5_of(type_name: str) -> str:
        return _spec.md5_hex(_spec.compute_md5_text(get(type_name), md5_of))

    return _spec.compute_md5_text(spec.spec, md5_of)


def compute_md5(msg_context: MsgContext, spec: Any) -> str:
    """genmsg's md5 sum of a message or service spec (its dependencies loaded)."""
    return _spec.md5_hex(compute_md5_text(msg_context, spec))


def compute_full_text(msg_context: MsgContext, spec: MsgSpec) -> str:
    """The ``message_definition``: the text, then every dependency once after a separator."""
    return _spec.compute_full_text(spec.spec, _get_spec(msg_context, spec.full_name))


def compute_full_type_name(package_name: str, file_name: str) -> str:
    """``('std_msgs', 'String.msg')`` -> ``'std_msgs/String'``."""
    for ext in (EXT_MSG, EXT_SRV):
        if file_name.endswith(ext):
            file_name = file_name[:-len(ext)]
            break
    return f"{package_name}/{file_name}"


# ---------------------------------------------------------------------------------------------
# the files a .msg/.srv depends on (genmsg.deps: what catkin lists as a generator's inputs)

def _dependency_files(context: MsgContext, full_names: Sequence[str]) -> List[Tuple[str, str]]:
    found = {(dep, context.get_file(dep) or "") for name in full_names
             for dep in context.get_all_depends(name)}
    return sorted(found)


def find_msg_dependencies_with_type(pkg_name: str, msg_file: str,
                                    search_paths: Dict[str, List[str]]) -> List[Tuple[str, str]]:
    """``(type, file)`` of every message ``msg_file`` (of package ``pkg_name``) depends on,
    directly or not, looked up in ``search_paths`` (``{package: [msg folders]}``)."""
    context = MsgContext.create_default()
    full_name = compute_full_type_name(pkg_name, os.path.basename(msg_file))
    spec = load_msg_from_file(context, msg_file, full_name)
    try:
        load_depends(context, spec, search_paths)
    except InvalidMsgSpec as exc:
        raise MsgGenerationException(f"Cannot read .msg for {full_name}: {exc}") from None
    return _dependency_files(context, [full_name])


def find_msg_dependencies(pkg_name: str, msg_file: str, search_paths: Dict[str, List[str]]) -> List[str]:
    """The files of the messages ``msg_file`` depends on."""
    return [path for _type, path in find_msg_dependencies_with_type(pkg_name, msg_file, search_paths)]


def find_srv_dependencies_with_type(pkg_name: str, srv_file: str,
                                    search_paths: Dict[str, List[str]]) -> List[Tuple[str, str]]:
    """``(type, file)`` of every message the request and response of ``srv_file`` depend on."""
    context = MsgContext.create_default()
    full_name = compute_full_type_name(pkg_name, os.path.basename(srv_file))
    spec = load_srv_from_file(context, srv_file, full_name)
    try:
        load_depends(context, spec, search_paths)
    except InvalidMsgSpec as exc:
        raise MsgGenerationException(f"Cannot read .msg for {full_name}: {exc}") from None
    return _dependency_files(context, [spec.request.full_name, spec.response.full_name])


def find_srv_dependencies(pkg_name: str, srv_file: str, search_paths: Dict[str, List[str]]) -> List[str]:
    return [path for _type, path in find_srv_dependencies_with_type(pkg_name, srv_file, search_paths)]
