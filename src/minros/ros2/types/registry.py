"""The ROS 2 type registry of one distro: bundled definitions, added ones, hashes, codecs.

:func:`registry` gives the shared registry of a distro (``jazzy``, ``kilted``, ``humble``) over
the definitions minros bundles (``share/<distro>/<pkg>/{msg,srv,action}``, taken verbatim from
upstream: ``share/<distro>/SOURCES.md``). It is read-only; :meth:`TypeRegistry.child` makes one
that also holds types of its own (a bag's definitions, types made from ROS 1 ones) without
changing the shared one. Types load on first use; everything is cached.

Any name rosidl describes is a struct here: ``pkg/msg/Name``; ``pkg/srv/Name`` and its
``_Request``, ``_Response``, ``_Event``; ``pkg/action/Name`` and its ``_Goal``, ``_Result``,
``_Feedback``, ``_SendGoal[_Request|_Response|_Event]``, ``_GetResult[...]``,
``_FeedbackMessage``.
"""

from __future__ import annotations

import threading
from pathlib import Path
from typing import Any, Dict, List, Optional, Sequence, Union

from minros.msgs.registry import UnknownTypeError
from minros.msgs.spec import MsgSpecError

from . import hashing
from .model import ActionType, Field, FieldType, MessageType, ServiceType, split_type_name
from .parse import make_service, parse_action, parse_msg, parse_srv

SHARE = Path(__file__).resolve().parent / "share"
DISTROS = ("humble", "jazzy", "kilted")
DEFAULT_DISTRO = "jazzy"

_SERVICE_PARTS = ("_Request", "_Response", "_Event")
#: suffixes of the structs derived from an action, longest first
_ACTION_PARTS = (
    "_SendGoal_Request", "_SendGoal_Response", "_SendGoal_Event", "_GetResult_Request",
    "_GetResult_Response", "_GetResult_Event", "_FeedbackMessage", "_SendGoal", "_GetResult",
    "_Feedback", "_Result", "_Goal",
)

Interface = Union[MessageType, ServiceType, ActionType]


def check_distro(distro: str) -> str:
    if distro not in DISTROS:
        raise ValueError(f"unknown ROS 2 distro {distro!r}: minros knows {', '.join(DISTROS)}")
    return distro


def service_struct(service: ServiceType) -> MessageType:
    """The struct rosidl describes a service as (its type hash is the service's)."""
    fields = [Field("request_message", FieldType(service.request.name)),
              Field("response_message", FieldType(service.response.name))]
    if service.event is not None:
        fields.append(Field("event_message", FieldType(service.event.name)))
    return MessageType(service.name, fields)


def action_struct(action: ActionType) -> MessageType:
    return MessageType(action.name, [
        Field("goal", FieldType(action.goal.name)),
        Field("result", FieldType(action.result.name)),
        Field("feedback", FieldType(action.feedback.name)),
        Field("send_goal_service", FieldType(action.send_goal.name)),
        Field("get_result_service", FieldType(action.get_result.name)),
        Field("feedback_message", FieldType(action.feedback_message.name)),
    ])


class TypeRegistry:
    """ROS 2 interface types of one distro, their descriptions, hashes and CDR codecs."""

    def __init__(self, distro: str = DEFAULT_DISTRO, paths: Sequence[Union[str, Path]] = (),
                 parent: Optional[TypeRegistry] = None, frozen: bool = False) -> None:
        self.distro = check_distro(distro)
        #: folders searched before the bundled definitions, each holding <pkg>/msg/*.msg ...
        self.paths = [Path(p) for p in paths]
        self.parent = parent
        self.frozen = frozen
        self._lock = threading.RLock()
        self._own: Dict[str, Interface] = {}  # added with add()
        self._loaded: Dict[str, Interface] = {}  # from files
        self._structs: Dict[str, MessageType] = {}
        self._hashes: Dict[str, str] = {}
        self._codecs: Dict[str, Any] = {}

    @property
    def has_type_hashes(self) -> bool:
        """Humble predates REP-2011: its endpoints and bags carry no type hash."""
        return self.distro != "humble"

    def child(self, paths: Sequence[Union[str, Path]] = ()) -> TypeRegistry:
        """A registry over this one that keeps the types added to it (and ``paths``) its own."""
        return TypeRegistry(self.distro, paths, parent=self)

    # -- adding ----------------------------------------------------------------------------------
    def add(self, interface: Interface) -> None:
        """Add a message, service or action type (replacing one of the same name here)."""
        if self.frozen:
            raise RuntimeError(f"the shared ROS 2 {self.distro} registry is read-only: add "
                               f"{interface.name} to registry.child() instead")
        with self._lock:
            self._own[interface.name] = interface
            self._structs.clear()
            self._hashes.clear()
            self._codecs.clear()

    def add_definition(self, kind: str, name: str, text: str,
                       origin: Optional[str] = None) -> Interface:
        """Parse and add a ``msg``, ``srv`` or ``action`` definition text."""
        parsed = self._parse(kind, name, text, origin)
        self.add(parsed)
        return parsed

    def _parse(self, kind: str, name: str, text: str, origin: Optional[str]) -> Interface:
        if kind == "msg":
            return parse_msg(text, name, origin)
        if kind == "srv":
            return parse_srv(text, name, origin, with_event=self.has_type_hashes)
        if kind == "action":
            return parse_action(text, name, origin, with_event=self.has_type_hashes)
        raise ValueError(f"unknown interface kind {kind!r}: expected msg, srv or action")

    # -- lookup ----------------------------------------------------------------------------------
    def _roots(self) -> List[Path]:
        return self.paths + ([SHARE / self.distro] if self.parent is None else [])

    def _interface(self, name: str, kind: str) -> Interface:
        """The message, service or action type ``name`` (``pkg/<kind>/Name``)."""
        found = self._own.get(name) or self._loaded.get(name)
        if found is not None:
            return found
        with self._lock:
            found = self._own.get(name) or self._loaded.get(name)
            if found is not None:
                return found
            package, _ns, short = name.split("/")
            for root in self._roots():
                path = root / package / kind / f"{short}.{kind}"
                if path.is_file():
                    try:
                        text = path.read_text(encoding="utf-8")
                    except (OSError, UnicodeDecodeError) as exc:
                        raise MsgSpecError(f"cannot read: {exc}", str(path)) from None
                    found = self._parse(kind, name, text, str(path))
                    self._loaded[name] = found
                    return found
            if self.parent is not None:
                return self.parent._interface(name, kind)
            raise self._unknown(name, kind)

    def _unknown(self, name: str, kind: str) -> UnknownTypeError:
        what = {"msg": "message", "srv": "service", "action": "action"}[kind]
        package = name.split("/")[0]
        where = [str(p) for p in self.paths] + [f"minros's bundled ROS 2 {self.distro} "
                                                 f"interfaces ({SHARE / self.distro})"]
        has_package = any((root / package).is_dir() for root in self._roots())
        reason = f"no {kind}/{name.rsplit('/', 1)[1]}.{kind} in package [{package}]" \
            if has_package else f"package [{package}] not found"
        return UnknownTypeError(name, f"Cannot locate ROS 2 {what} [{name}]: {reason} "
                                      f"(searched {', '.join(where)})")

    def message(self, name: str) -> MessageType:
        """The struct ``name``: a message (``pkg/msg/Name`` or ``pkg/Name``), or any part of a
        service or action (see the module docstring). Raises :class:`UnknownTypeError`."""
        try:
            package, ns, short = split_type_name(name)
        except ValueError as exc:
            raise UnknownTypeError(name, str(exc)) from None
        full = f"{package}/{ns}/{short}"
        found = self._structs.get(full)
        if found is not None:
            return found
        struct = self._resolve_struct(full, package, ns, short)
        self._structs[full] = struct
        return struct

    def _resolve_struct(self, full: str, package: str, ns: str, short: str) -> MessageType:
        if ns == "msg":
            interface = self._interface(full, "msg")
            assert isinstance(interface, MessageType)
            return interface
        if ns == "srv":
            for suffix in _SERVICE_PARTS:
                if short.endswith(suffix) and len(short) > len(suffix):
                    service = self.service(f"{package}/srv/{short[:-len(suffix)]}")
                    part = {"_Request": service.request, "_Response": service.response,
                            "_Event": service.event}[suffix]
                    if part is None:
                        raise UnknownTypeError(full, f"ROS 2 {self.distro} services have no "
                                                     f"_Event type: {full}")
                    return part
            return service_struct(self.service(full))
        if ns == "action":
            for suffix in _ACTION_PARTS:
                if short.endswith(suffix) and len(short) > len(suffix):
                    action = self.action(f"{package}/action/{short[:-len(suffix)]}")
                    return _action_part(action, suffix, full, self.distro)
            return action_struct(self.action(full))
        raise UnknownTypeError(full, f"invalid ROS 2 type name [{full}]: the namespace must be "
                                     f"msg, srv or action")

    def service(self, name: str) -> ServiceType:
        """Service type ``pkg/srv/Name`` (or ``pkg/Name``)."""
        package, _ns, short = split_type_name(name)
        found = self._interface(f"{package}/srv/{short}", "srv")
        assert isinstance(found, ServiceType)
        return found

    def action(self, name: str) -> ActionType:
        """Action type ``pkg/action/Name`` (or ``pkg/Name``)."""
        package, _ns, short = split_type_name(name)
        found = self._interface(f"{package}/action/{short}", "action")
        assert isinstance(found, ActionType)
        return found

    def has(self, name: str) -> bool:
        """Whether struct ``name`` can be found."""
        try:
            self.message(name)
        except UnknownTypeError:
            return False
        return True

    def type_names(self, kind: str = "msg") -> List[str]:
        """Names of the ``msg`` (or ``srv``, ``action``) types on file and added, sorted."""
        names = {n for n, i in self._own.items() if n.split("/")[1] == kind}
        for root in self._roots():
            if root.is_dir():
                for path in root.glob(f"*/{kind}/*.{kind}"):
                    names.add(f"{path.parent.parent.name}/{kind}/{path.stem}")
        if self.parent is not None:
            names.update(self.parent.type_names(kind))
        return sorted(names)

    # -- derived ---------------------------------------------------------------------------------
    def type_description(self, name: str) -> hashing.Description:
        """The full type description of ``name`` (as rosidl writes in its JSON files)."""
        return hashing.type_description(self.message(name).name, self.message)

    def type_hash(self, name: str) -> str:
        """The RIHS01 hash of ``name`` (``RIHS01_<64 hex>``); Humble has none (ValueError)."""
        if not self.has_type_hashes:
            raise ValueError("ROS 2 Humble has no type hashes (REP-2011 came with Iron): its "
                             "endpoints and bags carry none")
        full = self.message(name).name
        found = self._hashes.get(full)
        if found is None:
            found = hashing.type_hash(full, self.message)
            self._hashes[full] = found
        return found

    def codec(self, name: str) -> Any:
        """The CDR codec of struct ``name`` (:class:`minros.ros2.types.cdr.Codec`)."""
        full = self.message(name).name
        found = self._codecs.get(full)
        if found is None:
            from .cdr import build_codec

            with self._lock:
                found = self._codecs.get(full)
                if found is None:
                    found = build_codec(full, self.message, self.codec)
                    self._codecs[full] = found
        return found


def _action_part(action: ActionType, suffix: str, full: str, distro: str) -> MessageType:
    services = {"_SendGoal": action.send_goal, "_GetResult": action.get_result}
    for prefix, service in services.items():
        if suffix == prefix:
            return service_struct(service)
        if suffix.startswith(prefix + "_"):
            part = {"_Request": service.request, "_Response": service.response,
                    "_Event": service.event}[suffix[len(prefix):]]
            if part is None:
                raise UnknownTypeError(full, f"ROS 2 {distro} services have no _Event type")
            return part
    return {"_Goal": action.goal, "_Result": action.result, "_Feedback": action.feedback,
            "_FeedbackMessage": action.feedback_message}[suffix]


_registries: Dict[str, TypeRegistry] = {}
_registries_lock = threading.Lock()


def registry(distro: str = DEFAULT_DISTRO) -> TypeRegistry:
    """The shared, read-only registry of ``distro``'s bundled interfaces."""
    check_distro(distro)
    with _registries_lock:
        found = _registries.get(distro)
        if found is None:
            found = _registries[distro] = TypeRegistry(distro, frozen=True)
        return found


__all__ = ["DISTROS", "DEFAULT_DISTRO", "SHARE", "TypeRegistry", "registry", "make_service",
           "service_struct", "action_struct", "check_distro"]
