"""The message registry: finds definitions, computes md5 sums and full texts, builds classes.

A :class:`MsgContext` holds parsed specs and the classes generated from them. The global
context (:data:`REGISTRY`) loads ``pkg/msg/Type.msg`` and ``pkg/srv/Type.srv`` on demand from
the packages :func:`minros.packages.find_package` finds (ROS_PACKAGE_PATH, then the ones
minros ships); :func:`generate_dynamic` uses a private context filled from a
``message_definition`` text instead.
"""

from __future__ import annotations

import linecache
import os
import threading
from pathlib import Path
from typing import Any, Dict, List, Set, Tuple

from .codegen import generate_source, in_place_class_name, numpy_class_name
from .message import Message
from .spec import (
    ACTION_SUFFIXES,
    BUILTIN_TYPES,
    HEADER,
    HEADER_FULL_NAME,
    MsgSpec,
    MsgSpecError,
    SrvSpec,
    action_message_texts,
    compute_full_text,
    compute_md5_text,
    md5_hex,
    parse_msg,
    parse_srv,
    split_full_text,
)


class UnknownTypeError(LookupError):
    """A message or service type could not be found; the text says where minros looked."""

    def __init__(self, type_name: str, reason: str) -> None:
        self.type_name = type_name
        self.located = False  # True once the text names the file and line that use the type
        super().__init__(reason)


class ServiceDefinition:
    """Base of service classes: ``_type``, ``_md5sum``, ``_request_class``, ``_response_class``."""

    __slots__ = ()
    _type = ""
    _md5sum = ""
    _request_class: type = Message
    _response_class: type = Message


def normalize_type(type_name: str) -> str:
    """'Header' -> 'std_msgs/Header'; 'pkg/msg/Type' (ROS 2/rosbags style) -> 'pkg/Type'."""
    name = type_name.strip()
    if name == HEADER:
        return HEADER_FULL_NAME
    parts = name.split("/")
    if len(parts) == 3 and parts[1] in ("msg", "srv"):
        return f"{parts[0]}/{parts[2]}"
    return name


def _split_type(type_name: str, kind: str) -> Tuple[str, str]:
    package, sep, short = type_name.partition("/")
    if not sep or not package or not short or "/" in short:
        raise UnknownTypeError(type_name, f"invalid {kind} type [{type_name}]: expected 'package/Type'")
    return package, short


class MsgContext:
    """Specs, md5 sums, full texts and classes of a set of message types."""

    def __init__(self, search: bool = True, module_name: str | None = None,
                 fallback: MsgContext | None = None) -> None:
        self._search = search
        self._fallback = fallback
        self._module_name = module_name
        self._lock = threading.RLock()
        self._specs: Dict[str, MsgSpec] = {}
        self._srv_specs: Dict[str, SrvSpec] = {}
        self._from_srv: Dict[str, str] = {}  # Request/Response type -> service type
        self._md5: Dict[str, str] = {}
        self._classes: Dict[str, type] = {}
        self._numpy_classes: Dict[type, type] = {}
        self._in_place_classes: Dict[type, type] = {}
        self._srv_classes: Dict[str, type] = {}

    # -- specs -------------------------------------------------------------------------------
    def add_spec(self, spec: MsgSpec) -> None:
        with self._lock:
            self._specs[spec.full_name] = spec

    def _find_file(self, type_name: str, kind: str) -> Path:
        from minros.packages import BUILTIN_SHARE_DIRS, package_folders, ros_package_path

        package, short = _split_type(type_name, "service" if kind == "srv" else "message")
        if not self._search:
            raise UnknownTypeError(type_name, f"Cannot locate message [{type_name}]: "
                                              f"it is not part of the message definition")
        folders = package_folders(package)
        if not folders:
            where = [str(p) for p in ros_package_path()] + [str(p) for p in BUILTIN_SHARE_DIRS]
            raise UnknownTypeError(
                type_name, f"Cannot locate {'service' if kind == 'srv' else 'message'} "
                           f"[{type_name}]: package [{package}] not found (searched ROS_PACKAGE_PATH "
                           f"and minros's bundled packages: {', '.join(where) or 'nothing'})")
        # the first package of the name that has the file: an overlay that lacks a type (or a
        # whole msg/ or srv/ folder) falls back to its underlay, as in ROS
        for package_dir in folders:
            path = package_dir / kind / f"{short}.{kind}"
            if path.is_file():
                return path
        raise UnknownTypeError(
            type_name, f"Cannot locate {'service' if kind == 'srv' else 'message'} "
                       f"[{type_name}]: no file {kind}/{short}.{kind} in package "
                       f"[{package}] ({', '.join(map(str, folders))})")

    def get_spec(self, type_name: str) -> MsgSpec:
        """The spec of message type ``type_name`` (loads it on first use)."""
        type_name = normalize_type(type_name)
        spec = self._specs.get(type_name)
        if spec is not None:
            return spec
        with self._lock:
            spec = self._specs.get(type_name)
            if spec is not None:
                return spec
            if self._fallback is not None and not self._search:
                try:
                    spec = self._fallback.get_spec(type_name)
                except UnknownTypeError:
                    pass
                else:
                    self._specs[type_name] = spec
                    return spec
            try:
                path = self._find_file(type_name, "msg")
            except UnknownTypeError:
                generated = self._from_action(type_name)
                if generated is not None:
                    text, origin = generated
                    spec = parse_msg(text, type_name, origin)
                    self._specs[type_name] = spec
                    return spec
                for suffix in ("Request", "Response"):
                    if type_name.endswith(suffix) and len(type_name) > len(suffix):
                        try:
                            srv = self.get_srv_spec(type_name[:-len(suffix)])
                        except UnknownTypeError:
                            break
                        return srv.request if suffix == "Request" else srv.response
                raise
            text = _read_text(path)
            spec = parse_msg(text, type_name, str(path))
            self._specs[type_name] = spec
            return spec

    def _from_action(self, type_name: str) -> Tuple[str, str] | None:
        """(text, origin) of a message generated from an ``.action`` file, as catkin does."""
        if not self._search:
            return None
        from minros.packages import package_folders

        package, _, short = type_name.partition("/")
        for package_dir in package_folders(package) if package else []:
            for suffix in ACTION_SUFFIXES:
                if short.endswith(suffix) and len(short) > len(suffix):
                    base = short[:-len(suffix)]
                    path = package_dir / "action" / f"{base}.action"
                    if path.is_file():
                        texts = action_message_texts(_read_text(path), base)
                        return texts[short], f"{path} ({short} generated from it)"
        return None

    def get_srv_spec(self, type_name: str) -> SrvSpec:
        """The spec of service type ``type_name``."""
        type_name = normalize_type(type_name)
        spec = self._srv_specs.get(type_name)
        if spec is not None:
            return spec
        with self._lock:
            spec = self._srv_specs.get(type_name)
            if spec is not None:
                return spec
            path = self._find_file(type_name, "srv")
            spec = parse_srv(_read_text(path), type_name, str(path))
            self._srv_specs[type_name] = spec
            for part in (spec.request, spec.response):
                self._specs[part.full_name] = part
                self._from_srv[part.full_name] = type_name
            return spec

    # -- derived texts -------------------------------------------------------------------------
    def md5_text(self, type_name: str) -> str:
        return compute_md5_text(self.get_spec(type_name), self.md5sum)

    def md5sum(self, type_name: str) -> str:
        """genmsg's md5 sum of message type ``type_name``."""
        type_name = normalize_type(type_name)
        value = self._md5.get(type_name)
        if value is None:
            with self._lock:
                spec = self.get_spec(type_name)
                self._check_acyclic(spec)
                value = md5_hex(compute_md5_text(spec, self.md5sum))
                self._md5[type_name] = value
        return value

    def srv_md5sum(self, type_name: str) -> str:
        """md5 sum of service type ``type_name`` (request text + response text)."""
        spec = self.get_srv_spec(type_name)
        return md5_hex(compute_md5_text(spec.request, self.md5sum)
                       + compute_md5_text(spec.response, self.md5sum))

    def full_text(self, type_name: str) -> str:
        """The ``message_definition`` of message type ``type_name``."""
        return compute_full_text(self.get_spec(type_name), self.get_spec)

    def _check_acyclic(self, spec: MsgSpec) -> None:
        from .spec import all_dependencies

        all_dependencies(spec, self.get_spec)

    # -- classes -------------------------------------------------------------------------------
    def source(self, type_name: str, numpy: bool = False, in_place: bool = False) -> str:
        """The generated Python source of the class for ``type_name``."""
        type_name = normalize_type(type_name)
        spec = self.get_spec(type_name)
        return generate_source(spec, self.get_spec, self.md5sum(type_name),
                               self.full_text(type_name), self._module_for(type_name), numpy,
                               in_place)

    def _module_for(self, type_name: str) -> str | None:
        if self._module_name is not None:
            return self._module_name
        package = type_name.partition("/")[0]
        return f"{package}.srv" if type_name in self._from_srv else f"{package}.msg"

    def get_class(self, type_name: str) -> type:
        """The message class of ``type_name`` (generated and compiled once)."""
        cls = self._classes.get(type_name)
        if cls is not None:
            return cls
        type_name = normalize_type(type_name)
        with self._lock:
            cls = self._classes.get(type_name)
            if cls is None:
                try:
                    source = self.source(type_name)
                except UnknownTypeError as exc:
                    if exc.type_name == type_name or exc.located:
                        raise
                    raise self._unknown_field_type(type_name, exc) from None
                cls = self._compile(type_name, source, None)
                self._classes[type_name] = cls
            return cls

    def _unknown_field_type(self, type_name: str, exc: UnknownTypeError) -> UnknownTypeError:
        """``exc`` (type ``exc.type_name`` not found while building ``type_name``) restated
        from the field that names the missing type: its file and line, and a likely fix."""
        missing = exc.type_name
        found = self._referrer(type_name, missing)
        if found is None:
            spec = self._specs.get(type_name)
            where = f" in {spec.filename}" if spec is not None and spec.filename else ""
            error = UnknownTypeError(missing, f"{exc} (needed by {type_name}{where})")
        else:
            spec, field = found
            line = spec.field_lines.get(field.name)
            where = (spec.filename or spec.full_name) + (f":{line}" if line else "")
            reason = str(exc)
            if reason.startswith("Cannot locate") and "]: " in reason:
                reason = reason.split("]: ", 1)[1]
            text = (f"{where}: field [{field.name}] of {spec.full_name} has unknown type "
                    f"[{missing}]: {reason}{_did_you_mean(missing)}")
            if spec.full_name != type_name:
                text += f" (needed by {type_name})"
            error = UnknownTypeError(missing, text)
        error.located = True
        return error

    def _referrer(self, root: str, missing: str) -> Tuple[MsgSpec, Any] | None:
        """The loaded spec (reached from ``root``) and its field whose type is ``missing``."""
        queue, seen = [root], {root}
        while queue:
            spec = self._specs.get(queue.pop(0))
            if spec is None:
                continue
            for field in spec.fields:
                if field.is_builtin:
                    continue
                if field.base_type == missing:
                    return spec, field
                if field.base_type not in seen:
                    seen.add(field.base_type)
                    queue.append(field.base_type)
        return None

    def get_numpy_class(self, cls: Any) -> type:
        """The ``numpy_msg`` variant of message class ``cls``."""
        found = self._numpy_classes.get(cls)
        if found is not None:
            return found
        if cls in self._numpy_classes.values():
            return cls  # already a numpy variant
        with self._lock:
            found = self._numpy_classes.get(cls)
            if found is None:
                found = self._compile(cls._type, self.source(cls._type, numpy=True), cls)
                self._numpy_classes[cls] = found
            return found

    def get_in_place_class(self, cls: Any) -> type:
        """The variant of message class ``cls`` whose byte arrays deserialize as views of the
        data (its deserializers are used on instances of ``cls``: ``reader_for(cls, True)``)."""
        found = self._in_place_classes.get(cls)
        if found is None:
            with self._lock:
                found = self._in_place_classes.get(cls)
                if found is None:
                    found = self._compile(cls._type, self.source(cls._type, in_place=True), cls,
                                          in_place_class_name(cls._type))
                    self._in_place_classes[cls] = found
        return found

    def _compile(self, type_name: str, source: str, base_class: type | None,
                 name: str | None = None) -> type:
        variant = "" if base_class is None else " in place" if name else " numpy"
        filename = f"<minros msg {type_name}{variant}>"
        linecache.cache[filename] = (len(source), None, source.splitlines(True), filename)
        namespace: Dict[str, Any] = {"_load": self.get_class}  # embedded types from this context
        namespace["__name__"] = self._module_for(type_name) or "minros.msgs.generated"
        if base_class is not None:
            namespace["_base_class"] = base_class
        exec(compile(source, filename, "exec"), namespace)
        if name is None:
            name = numpy_class_name(type_name) if base_class is not None else type_name.rpartition("/")[2]
        cls = namespace[name]
        cls._context = self  # numpy_msg() and tools find the registry a class came from
        return cls

    def get_service_class(self, type_name: str) -> type:
        """The service class of ``type_name`` with its request and response classes."""
        type_name = normalize_type(type_name)
        cls = self._srv_classes.get(type_name)
        if cls is not None:
            return cls
        with self._lock:
            cls = self._srv_classes.get(type_name)
            if cls is not None:
                return cls
            spec = self.get_srv_spec(type_name)
            request = self.get_class(spec.request.full_name)
            response = self.get_class(spec.response.full_name)
            cls = type(spec.short_name, (ServiceDefinition,), {
                "__slots__": (),
                "__module__": f"{spec.package}.srv",
                "__doc__": f"{type_name} (md5sum {self.srv_md5sum(type_name)}).",
                "_type": type_name,
                "_md5sum": self.srv_md5sum(type_name),
                "_request_class": request,
                "_response_class": response,
            })
            self._srv_classes[type_name] = cls
            return cls


def _did_you_mean(type_name: str) -> str:
    """``; did you mean [string]?`` for a misspelled type: the closest primitive, or type of
    the same package."""
    import difflib

    package, _, short = type_name.rpartition("/")
    candidates = sorted(BUILTIN_TYPES) + ["Header"]
    try:
        candidates += [name.rpartition("/")[2] for name in list_types(package)]
    except UnknownTypeError:
        pass
    close = difflib.get_close_matches(short, candidates, n=1, cutoff=0.75)
    return f"; did you mean [{close[0]}]?" if close else ""


def _read_text(path: Path) -> str:
    try:
        return path.read_text(encoding="utf-8")
    except (OSError, UnicodeDecodeError) as exc:
        raise MsgSpecError(f"cannot read: {exc}", str(path)) from None


#: The process-wide registry of message and service types.
REGISTRY = MsgContext()
Message._context = REGISTRY  # hand-written subclasses of Message load from the global registry


def get_message_class(type_name: str) -> type:
    """The class of message type ``type_name`` ('pkg/Type'); raises :class:`UnknownTypeError`."""
    return REGISTRY.get_class(type_name)


def get_service_class(type_name: str) -> type:
    """The class of service type ``type_name``; raises :class:`UnknownTypeError`."""
    return REGISTRY.get_service_class(type_name)


def import_class(type_name: str, kind: str = "msg") -> Any:
    """genpy's lookup: the class ``Type`` of module ``<pkg>.msg`` (``.srv`` for ``kind='srv'``)
    or None when there is none, so a genpy-generated package on sys.path is found as in ROS,
    and minros's own classes through its stand-in packages. ``'time'``/``'duration'`` give
    Time/Duration; ``'Header'`` means std_msgs/Header; a name without a package is a
    ``ValueError``. A malformed definition raises :class:`MsgSpecError` naming its file.
    """
    import importlib

    from .tval import Duration, Time

    if kind == "msg" and type_name == "time":
        return Time
    if kind == "msg" and type_name == "duration":
        return Duration
    package, _, base = type_name.rpartition("/")
    if not package:
        if base != "Header":
            raise ValueError(f"message type is missing package name: {type_name}")
        package = "std_msgs"
    try:
        module = importlib.import_module(f"{package}.{kind}")
    except ImportError:
        return None
    return getattr(module, base, None)


def numpy_msg(cls: type) -> type:
    """The variant of message class ``cls`` whose numeric arrays deserialize as numpy views."""
    return (getattr(cls, "_context", None) or REGISTRY).get_numpy_class(cls)


_dynamic_cache: Dict[Tuple[str, str], Dict[str, type]] = {}
_dynamic_lock = threading.Lock()


def generate_dynamic(core_type: str, full_text: str) -> Dict[str, type]:
    """Classes for ``core_type`` and every type in its ``message_definition`` text.

    The equivalent of genpy.dynamic.generate_dynamic (what rostopic echo and rosbag use):
    the text is split on the 80-'=' lines and ``MSG: pkg/Type`` headers; the result maps
    each type name to a fresh class (not registered globally).
    """
    key = (core_type, full_text)
    with _dynamic_lock:
        found = _dynamic_cache.get(key)
    if found is not None:
        return dict(found)
    # types the text lacks (a sloppy publisher or bag) come from the installed definitions
    context = MsgContext(search=False, module_name="minros.msgs.dynamic", fallback=REGISTRY)
    core_type = normalize_type(core_type)
    blocks = split_full_text(full_text)
    types: List[str] = []
    for block_type, text in blocks:
        name = core_type if block_type is None else normalize_type(block_type)
        context.add_spec(parse_msg(text, name, f"<message_definition of {core_type}: {name}>"))
        types.append(name)
    classes = {name: context.get_class(name) for name in types}
    with _dynamic_lock:
        if len(_dynamic_cache) > 256:
            _dynamic_cache.clear()
        _dynamic_cache[key] = classes
    return dict(classes)


# ---------------------------------------------------------------------------------------------
# text for people (rosmsg show / rossrv show)

def spec_to_text(spec: MsgSpec, context: MsgContext | None = None, indent: str = "") -> str:
    """rosmsg's expanded, comment-free view: constants, fields, embedded types indented."""
    ctx = context or REGISTRY
    lines: List[str] = []
    for c in spec.constants:
        lines.append(f"{indent}{c.type} {c.name}={c.val_text}\n")
    for f in spec.fields:
        lines.append(f"{indent}{f.type} {f.name}\n")
        if not f.is_builtin:
            lines.append(spec_to_text(ctx.get_spec(f.base_type), ctx, indent + "  "))
    return "".join(lines)


def message_text(type_name: str, raw: bool = False) -> str:
    """What ``rosmsg show [-r] TYPE`` prints (without print's final newline)."""
    spec = REGISTRY.get_spec(type_name)
    REGISTRY.full_text(type_name)  # loads every embedded type: errors surface here
    return spec.text if raw else spec_to_text(spec)


def service_text(type_name: str, raw: bool = False) -> str:
    """What ``rossrv show [-r] TYPE`` prints (without print's final newline)."""
    spec = REGISTRY.get_srv_spec(type_name)
    if raw:
        return spec.text
    REGISTRY.full_text(spec.request.full_name)
    REGISTRY.full_text(spec.response.full_name)
    return spec_to_text(spec.request) + "---\n" + spec_to_text(spec.response)


def packages_with(kind: str) -> Dict[str, Path]:
    """Packages holding a ``msg`` (or ``srv``) folder: ``{name: folder}``, sorted by name."""
    from minros.packages import list_packages

    found = {name: path / kind for name, path in list_packages(refresh=True).items()}
    return {name: found[name] for name in sorted(found) if found[name].is_dir()}


def list_types(package: str, kind: str = "msg") -> List[str]:
    """``pkg/Type`` names of the message (or service) types of ``package``, sorted."""
    from minros.packages import find_package

    package_dir = find_package(package)
    if package_dir is None:
        raise UnknownTypeError(package, f"package [{package}] not found")
    return [f"{package}/{name}" for name in type_names_in(package_dir, kind)]


def type_names_in(package_dir: Path, kind: str = "msg") -> List[str]:
    """Short names of the ``.msg`` (or ``.srv``) types of a package folder, sorted; for
    messages this includes the ones generated from ``action/*.action`` files."""
    names: Set[str] = set()
    suffix = "." + kind
    try:
        names.update(p[:-len(suffix)] for p in os.listdir(package_dir / kind) if p.endswith(suffix))
    except OSError:
        pass
    if kind == "msg":
        try:
            actions = [p[:-7] for p in os.listdir(package_dir / "action") if p.endswith(".action")]
        except OSError:
            actions = []
        for base in actions:
            names.update(base + s for s in ACTION_SUFFIXES)
    return sorted(names)
