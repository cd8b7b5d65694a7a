"""ROS 1 <-> ROS 2 type mapping, by ros1_bridge's rules, and ROS 2 types made from ROS 1 ones.

Which ROS 2 type a ROS 1 type ``pkg/Name`` becomes (:meth:`Mapper.message`), first match wins:

1. ``std_msgs/Time`` and ``std_msgs/Duration`` become ``builtin_interfaces/msg/Time|Duration``
   (ros1_bridge maps them explicitly);
2. a ros1_bridge mapping rule naming it (the YAML files ROS 2 packages ship: ``tf/tfMessage`` ->
   ``tf2_msgs/msg/TFMessage``, ``rosgraph_msgs/Log`` -> ``rcl_interfaces/msg/Log``,
   ``uuid_msgs/UniqueID`` -> ``unique_identifier_msgs/msg/UUID``; more can be given);
3. the same name in a paired ROS 2 package: the same package name, or ``X_msgs`` <->
   ``X_msgs``/``X_interfaces`` (ros1_bridge pairs only these; the same name is minros's
   addition, so ``turtlesim`` and ``std_srvs`` pair), or a package rule;
4. none: a ROS 2 type made from the ROS 1 definition (what ros1_bridge cannot do), named
   ``pkg/msg/Name``: each field keeps its type spelling (``byte`` stays ``byte``, i.e. octet;
   ``char`` stays ``char``, i.e. uint8: the definition means what it would mean copied into a
   ROS 2 package), ``time``/``duration`` become ``builtin_interfaces/Time|Duration``, nested
   types become their own ROS 2 counterparts (``Header`` -> ``std_msgs/Header``, without
   ``seq``), field names are lower-cased (ROS 2 requires lower case; ``D`` -> ``d``; two
   names equal but for case -> no mapping), constants are kept, an empty definition gets
   rosidl's placeholder member. So a ROS 1 package ported to ROS 2 by copying its ``.msg``
   files (names already lower case) has the same type hash.

Fields pair as ros1_bridge pairs them: a rule's ``fields_1_to_2`` first (a ROS 1 path such as
``header.stamp`` to a ROS 2 member), then every ROS 1 field whose lower-cased name is a ROS 2
member's. ROS 1 fields with no partner are dropped (Header's ``seq``); ROS 2 members with none
take their default (sensor_msgs/Range's ``variance``); both at once is no mapping, with the
reason. (ros1_bridge forgets rule-mapped members in that last check, so its own Log rule never
applies; here it does.) Paired fields must agree: the same primitive (any two of ``byte``,
``char``, ``int8``, ``uint8`` are one byte copied), ``string`` to a ``string`` (a bound is checked),
``time``/``duration`` to ``builtin_interfaces/Time|Duration``, nested to a mapped nested type,
``T[]`` to ``T[]``/``T[<=N]``, ``T[N]`` to ``T[N]``.

Time: ROS 1 ``time`` has uint32 ``secs``, ROS 2's int32 ``sec``. Both are carried bit for bit,
as ros1_bridge's C++ assignment does: a ROS 1 time from 2038-01-19 on (secs >= 2^31) arrives as
a negative ``sec``, and a negative ROS 2 ``sec`` arrives as ``secs + 2^32``; every value round
trips exactly. ``nsecs``/``nanosec`` are copied as they are (no normalisation either way).

Header's ``seq``: ROS 2 has none. ros1_bridge writes 0 (its roscpp publisher does not count);
minros's converters take the value to write (:meth:`Transcoder.cdr_to_ros1`'s ``seq``), so the
bridge and bag conversion count per publisher or topic as rospy does (1, 2, ...). Nested
headers (in arrays, say) get 0.

Services map request and response the same way; actions their goal, result and feedback
(:class:`ActionMapping` says what ROS 1's actionlib protocol has that no field mapping carries).
A bag's own definitions go through :meth:`Mapper.add_ros1_definition` and then the same rules.
"""

from __future__ import annotations

import threading
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Dict, Iterable, List, Mapping, Optional, Sequence, Tuple, Union

from minros.msgs.registry import REGISTRY, MsgContext, UnknownTypeError, normalize_type
from minros.msgs.spec import Field as Ros1Field
from minros.msgs.spec import MsgSpec, MsgSpecError, parse_msg, split_full_text

from .model import (
    ARRAY,
    BOUNDED,
    EMPTY_MEMBER,
    SCALAR,
    SEQUENCE,
    Constant,
    Field,
    FieldType,
    MessageType,
)
from .parse import make_action, make_service
from .registry import SHARE, TypeRegistry, registry

TIME = "builtin_interfaces/msg/Time"
DURATION = "builtin_interfaces/msg/Duration"
#: ROS 1 types any two of which are one byte copied bit for bit
ONE_BYTE = frozenset(("byte", "char", "int8", "uint8"))
ROS1_PRIMITIVES = frozenset(("int8", "uint8", "int16", "uint16", "int32", "uint32", "int64",
                             "uint64", "float32", "float64", "bool", "char", "byte"))

# ROS 1's time and duration as structs of two fields, so they map like any nested type
_TIME_SPECS = {
    "time": MsgSpec("time", [Ros1Field("secs", "uint32"), Ros1Field("nsecs", "uint32")], [], ""),
    "duration": MsgSpec("duration", [Ros1Field("secs", "int32"), Ros1Field("nsecs", "int32")],
                        [], ""),
}
_TIME_FIELDS = {"secs": "sec", "nsecs": "nanosec"}


class NoMappingError(LookupError):
    """A ROS 1 type has no ROS 2 counterpart that the rules can map; ``reason`` says why."""

    def __init__(self, ros1_type: str, reason: str) -> None:
        self.ros1_type = ros1_type
        self.reason = reason
        super().__init__(f"{ros1_type}: {reason}")


@dataclass
class Link:
    """One ROS 2 member and where its value comes from in the ROS 1 message."""

    ros2: Field
    #: the ROS 1 field path from the mapped message (``("header", "stamp")``); None: the
    #: member exists only in ROS 2 and takes its default
    ros1_path: Optional[Tuple[str, ...]] = None
    ros1_field: Optional[Ros1Field] = None
    #: the mapping of a nested type (or array element type), time/duration included
    nested: Optional[MessageMapping] = None


@dataclass
class MessageMapping:
    """How one ROS 1 message type and one ROS 2 struct correspond, field by field."""

    ros1_type: str
    ros2_type: str
    links: List[Link]
    #: ROS 1 fields with no ROS 2 partner (dropped going to ROS 2, zero coming back)
    dropped: List[str]
    #: ROS 2 members with no ROS 1 partner (their default going to ROS 2)
    defaulted: List[str]
    #: True when the ROS 2 type was made from the ROS 1 definition
    generated: bool
    mapper: Mapper = field(repr=False)
    _transcoder: Any = field(default=None, repr=False)

    @property
    def ros2(self) -> MessageType:
        return self.mapper.ros2.message(self.ros2_type)

    @property
    def ros1(self) -> MsgSpec:
        return self.mapper.ros1_spec(self.ros1_type)

    def all_dropped(self, prefix: str = "") -> List[str]:
        """Dropped ROS 1 field paths, nested ones included (``header.seq``, ``poses[].header.seq``)."""
        out = [prefix + name for name in self.dropped]
        for link in self.links:
            if link.nested is not None and link.ros1_field is not None and link.ros1_path:
                path = ".".join(link.ros1_path) + ("[]" if link.ros1_field.is_array else "")
                out += link.nested.all_dropped(prefix + path + ".")
        return out

    def all_defaulted(self, prefix: str = "") -> List[str]:
        """ROS 2 members taking defaults, nested ones included."""
        out = [prefix + name for name in self.defaulted]
        for link in self.links:
            if link.nested is not None and link.ros1_path:
                path = link.ros2.name + ("[]" if link.ros2.type.is_array else "")
                out += link.nested.all_defaulted(prefix + path + ".")
        return out

    @property
    def type_hash(self) -> str:
        return self.mapper.ros2.type_hash(self.ros2_type)

    @property
    def dds_type_name(self) -> str:
        from .model import dds_type_name

        return dds_type_name(self.ros2_type)

    @property
    def transcoder(self) -> Any:
        """The :class:`minros.ros2.types.transcode.Transcoder` of this pair (built once)."""
        if self._transcoder is None:
            from .transcode import build_transcoder

            self._transcoder = build_transcoder(self)
        return self._transcoder


@dataclass
class ServiceMapping:
    ros1_type: str  # pkg/Name
    ros2_type: str  # pkg/srv/Name
    request: MessageMapping
    response: MessageMapping
    generated: bool


#: ROS 1 actionlib_msgs/GoalStatus codes -> ROS 2 action_msgs/GoalStatus codes
#: (REJECTED has none: ROS 2 rejects in the SendGoal response, accepted=false)
ACTION_STATUS_1_TO_2 = {0: 1, 1: 2, 2: 5, 3: 4, 4: 6, 6: 3, 7: 3, 8: 5, 9: 0}
#: ROS 2 action_msgs/GoalStatus codes -> ROS 1's
ACTION_STATUS_2_TO_1 = {0: 9, 1: 0, 2: 1, 3: 6, 4: 3, 5: 2, 6: 4}


@dataclass
class ActionMapping:
    """A ROS 1 action (actionlib) and a ROS 2 action: the parts that map field by field, and
    what the two protocols do differently (``notes``), which a bridge must translate itself."""

    ros1_type: str
    ros2_type: str
    goal: MessageMapping
    result: MessageMapping
    feedback: MessageMapping
    generated: bool
    notes: List[str]


ACTION_NOTES = [
    "ROS 1 actionlib runs over five topics (goal, cancel, status, feedback, result) with "
    "<Name>ActionGoal/Result/Feedback envelopes; ROS 2 over three services (send_goal, "
    "cancel_goal, get_result) and two topics (feedback, status): the envelopes do not map "
    "field by field, the bridge translates the protocol",
    "actionlib_msgs/GoalID (stamp + string id) has no field mapping to ROS 2's goal id "
    "(unique_identifier_msgs/UUID, 16 bytes): a bridge keeps a table of both",
    "actionlib_msgs/GoalStatus and action_msgs/GoalStatus number their states differently: "
    "ACTION_STATUS_1_TO_2 / ACTION_STATUS_2_TO_1; ROS 1's REJECTED is ROS 2's "
    "SendGoal response accepted=false",
    "ROS 2's actionlib_msgs (GoalID, GoalStatus, GoalStatusArray) map field by field to ROS 1's: "
    "ROS 1 action topics bridge as plain topics",
]


def _ros2_kind(f1: Ros1Field) -> str:
    return SCALAR if not f1.is_array else SEQUENCE if f1.array_len is None else ARRAY


class Mapper:
    """Maps ROS 1 types (of ``ros1``, minros's registry by default) to ROS 2 types (of a child
    of the ``distro``'s registry, where the types it makes go)."""

    def __init__(self, distro: str = "jazzy", ros1: Optional[MsgContext] = None,
                 ros2: Optional[TypeRegistry] = None,
                 rules: Iterable[Mapping[str, Any]] = (), generate: bool = True,
                 bundled_rules: bool = True) -> None:
        self.ros2 = ros2 if ros2 is not None else registry(distro).child()
        self.distro = self.ros2.distro
        self._base_ros1 = ros1 or REGISTRY
        self._own_ros1 = MsgContext(search=False, module_name="minros.ros2.bridged",
                                    fallback=self._base_ros1)
        self.ros1_context = self._own_ros1
        self.generate = generate
        self._lock = threading.RLock()
        self._pairs: Dict[Tuple[str, str], Union[MessageMapping, NoMappingError]] = {}
        self._messages: Dict[str, Union[MessageMapping, NoMappingError]] = {}
        self._services: Dict[str, Union[ServiceMapping, NoMappingError]] = {}
        self._message_rules: Dict[Tuple[str, str], Tuple[str, Optional[Dict[str, str]]]] = {}
        self._service_rules: Dict[Tuple[str, str], Tuple[str, Dict[str, str], Dict[str, str]]] = {}
        self._package_rules: Dict[str, List[str]] = {}
        self._building: List[str] = []
        if bundled_rules:
            for path in sorted((SHARE / self.distro).glob("*/*.yaml")):
                self.add_rules(_load_yaml(path))
        self.add_rules(rules)

    # -- inputs ----------------------------------------------------------------------------------
    def add_rules(self, rules: Iterable[Mapping[str, Any]]) -> None:
        """Add ros1_bridge mapping rules (the dicts of its YAML files)."""
        for rule in rules:
            p1, p2 = rule.get("ros1_package_name"), rule.get("ros2_package_name")
            if not p1 or not p2:
                raise ValueError(f"a mapping rule needs ros1_package_name and "
                                 f"ros2_package_name: {dict(rule)}")
            if "ros1_message_name" in rule or "ros2_message_name" in rule:
                fields = dict(rule.get("fields_1_to_2") or {})
                fields.update({v: k for k, v in (rule.get("fields_2_to_1") or {}).items()})
                self._message_rules[(p1, rule["ros1_message_name"])] = (
                    f"{p2}/msg/{rule['ros2_message_name']}", fields or None)
            elif "ros1_service_name" in rule or "ros2_service_name" in rule:
                self._service_rules[(p1, rule["ros1_service_name"])] = (
                    f"{p2}/srv/{rule['ros2_service_name']}",
                    dict(rule.get("request_fields_1_to_2") or {}),
                    dict(rule.get("response_fields_1_to_2") or {}))
            else:
                self._package_rules.setdefault(p1, []).append(p2)
        self._forget()

    def add_ros1_definition(self, ros1_type: str, full_text: str) -> List[str]:
        """Make a ROS 1 type (and the types in its ``message_definition`` text, as a bag or a
        connection header carries it) known to this mapper; returns their names. These
        definitions win over installed ones of the same name."""
        core = normalize_type(ros1_type)
        names = []
        for block_type, text in split_full_text(full_text):
            name = core if block_type is None else normalize_type(block_type)
            self._own_ros1.add_spec(parse_msg(text, name, f"<message_definition of {core}: "
                                                          f"{name}>"))
            names.append(name)
        self._forget()
        return names

    def _forget(self) -> None:
        with self._lock:
            self._pairs.clear()
            self._messages.clear()
            self._services.clear()

    def ros1_spec(self, ros1_type: str) -> MsgSpec:
        if ros1_type in _TIME_SPECS:
            return _TIME_SPECS[ros1_type]
        return self.ros1_context.get_spec(ros1_type)

    # -- messages --------------------------------------------------------------------------------
    def message(self, ros1_type: str) -> MessageMapping:
        """The mapping of ROS 1 message type ``ros1_type`` (``pkg/Name``); raises
        :class:`NoMappingError` with the reason, or :class:`UnknownTypeError`."""
        name = normalize_type(ros1_type)
        found = self._messages.get(name)
        if found is None:
            with self._lock:
                found = self._messages.get(name)
                if found is None:
                    try:
                        found = self._message(name)
                    except NoMappingError as exc:
                        found = exc
                    self._messages[name] = found
        if isinstance(found, NoMappingError):
            raise found
        return found

    def ros2_type_for(self, ros1_type: str) -> str:
        """The ROS 2 type name ROS 1 type ``ros1_type`` maps to."""
        return self.message(ros1_type).ros2_type

    def _message(self, name: str) -> MessageMapping:
        if name in _TIME_SPECS:
            return self._pair(name, TIME if name == "time" else DURATION, _TIME_FIELDS)
        if name in self._building:
            raise NoMappingError(name, f"recursive definition: {' -> '.join(self._building)}")
        self.ros1_spec(name)  # UnknownTypeError first
        counterpart = self._counterpart(name)
        if counterpart is not None:
            ros2_name, rule_fields = counterpart
            return self._pair(name, ros2_name, rule_fields)
        if not self.generate:
            raise NoMappingError(name, "no ROS 2 type of that package and name (and making "
                                       "one from the ROS 1 definition is off)")
        package, _, short = name.partition("/")
        ros2_name = f"{package}/msg/{short}"
        self._building.append(name)
        try:
            self.ros2.add(self._make_ros2(self.ros1_spec(name), ros2_name))
        finally:
            self._building.pop()
        mapping = self._pair(name, ros2_name, None)
        mapping.generated = True
        return mapping

    def _counterpart(self, name: str) -> Optional[Tuple[str, Optional[Dict[str, str]]]]:
        package, _, short = name.partition("/")
        if name in ("std_msgs/Time", "std_msgs/Duration"):
            return (TIME if short == "Time" else DURATION,
                    {f"data.{k}": v for k, v in _TIME_FIELDS.items()})
        rule = self._message_rules.get((package, short))
        if rule is not None and self.ros2.has(rule[0]):
            return rule
        for candidate in self._ros2_packages(package):
            ros2_name = f"{candidate}/msg/{short}"
            if self.ros2.has(ros2_name):
                return ros2_name, None
        return None

    def _ros2_packages(self, package: str) -> List[str]:
        out = [package]
        if package.endswith("_msgs"):
            base = package[:-len("_msgs")]
            out += [base + "_interfaces"]
        out += self._package_rules.get(package, [])
        return out

    def _make_ros2(self, spec: MsgSpec, ros2_name: str) -> MessageType:
        """A ROS 2 struct made from a ROS 1 definition (the rules of the module docstring)."""
        fields: List[Field] = []
        seen: Dict[str, str] = {}
        for f1 in spec.fields:
            lowered = f1.name.lower()
            if lowered in seen:
                raise NoMappingError(spec.full_name, f"fields {seen[lowered]!r} and {f1.name!r} "
                                                     f"are one name in ROS 2 (lower case)")
            seen[lowered] = f1.name
            base = f1.base_type
            if base in ROS1_PRIMITIVES or base == "string":
                ros2_base = base
            elif base in _TIME_SPECS:
                ros2_base = TIME if base == "time" else DURATION
            else:
                try:
                    ros2_base = self.message(base).ros2_type
                except NoMappingError as exc:
                    raise NoMappingError(spec.full_name, f"field {f1.name} ({f1.type}): "
                                                         f"{exc.reason}") from None
            fields.append(Field(lowered, FieldType(ros2_base, _ros2_kind(f1), f1.array_len or 0)))
        if not fields:
            fields.append(Field(EMPTY_MEMBER, FieldType("uint8")))
        constants = [Constant(c.name, c.type, c.value) for c in spec.constants]  # type: ignore[arg-type]
        text = ros2_msg_text(fields, constants)
        return MessageType(ros2_name, fields, constants, text,
                           f"made by minros from ROS 1's {spec.full_name}")

    def _pair(self, ros1_name: str, ros2_name: str,
              rule_fields: Optional[Mapping[str, str]]) -> MessageMapping:
        key = (ros1_name, ros2_name)
        found = self._pairs.get(key)
        if found is None:
            try:
                found = self._build_pair(ros1_name, ros2_name, rule_fields)
            except NoMappingError as exc:
                found = exc
            self._pairs[key] = found
        if isinstance(found, NoMappingError):
            raise found
        return found

    def _build_pair(self, ros1_name: str, ros2_name: str,
                    rule_fields: Optional[Mapping[str, str]]) -> MessageMapping:
        spec = self.ros1_spec(ros1_name)
        struct = self.ros2.message(ros2_name)
        sources: Dict[str, Tuple[str, ...]] = {}  # ROS 2 member -> ROS 1 path
        for rule_path, member in (rule_fields or {}).items():
            if struct.field(member) is None:
                raise NoMappingError(ros1_name, f"mapping rule names ROS 2 field {member!r}, "
                                                f"which {ros2_name} lacks")
            sources[member] = tuple(rule_path.split("."))
        used_roots = {p[0] for p in sources.values()}
        dropped: List[str] = self._partly_dropped(spec, [p for p in sources.values()
                                                         if len(p) > 1], ())
        for f1 in spec.fields:
            if f1.name in used_roots:
                continue
            # ros1_bridge's lower-cased name; or the same name, for ROS 2 types written with
            # ROS 1's names (rosbags-convert stores custom types so, ``Name`` and all)
            partner = struct.field(f1.name.lower()) or struct.field(f1.name)
            if partner is None or partner.name in sources:
                dropped.append(f1.name)
            else:
                sources[partner.name] = (f1.name,)
        defaulted = [f.name for f in struct.fields if f.name not in sources
                     and not (f.name == EMPTY_MEMBER and struct.is_empty)]
        if dropped and defaulted:
            raise NoMappingError(ros1_name, f"ROS 1 field(s) {', '.join(dropped)} and "
                                            f"{ros2_name} field(s) {', '.join(defaulted)} have "
                                            f"no partner (renamed? a mapping rule "
                                            f"(fields_1_to_2) can pair them)")
        links: List[Link] = []
        for f2 in struct.fields:
            path = sources.get(f2.name)
            if path is None:
                links.append(Link(f2))
                continue
            f1, parent = self._resolve_path(spec, path, ros1_name)
            nested = self._check_link(ros1_name, ".".join(path), f1, f2, parent in _TIME_SPECS)
            links.append(Link(f2, path, f1, nested))
        self._check_order(ros1_name, spec, links)
        return MessageMapping(ros1_name, ros2_name, links, dropped, defaulted, False, self)

    def _partly_dropped(self, spec: MsgSpec, paths: List[Tuple[str, ...]],
                        prefix: Tuple[str, ...]) -> List[str]:
        """The fields of messages a rule path goes through that no path reaches
        (``header.seq`` and ``header.frame_id`` for ``header.stamp``)."""
        out: List[str] = []
        for f1 in spec.fields:
            path = prefix + (f1.name,)
            deeper = [p for p in paths if p[:len(path)] == path and len(p) > len(path)]
            if deeper:
                out += self._partly_dropped(self.ros1_spec(f1.base_type), deeper, path)
            elif prefix and path not in paths:
                out.append(".".join(path))
        return out

    def _resolve_path(self, spec: MsgSpec, path: Tuple[str, ...],
                      ros1_name: str) -> Tuple[Ros1Field, str]:
        """The ROS 1 field at ``path`` and the name of the message holding it."""
        current = spec
        f1: Optional[Ros1Field] = None
        for depth, part in enumerate(path):
            f1 = next((f for f in current.fields if f.name == part), None)
            if f1 is None:
                raise NoMappingError(ros1_name, f"mapping rule names ROS 1 field "
                                                f"{'.'.join(path)!r}, which does not exist")
            if depth < len(path) - 1:
                if f1.is_array or f1.base_type in ROS1_PRIMITIVES or f1.base_type == "string":
                    raise NoMappingError(ros1_name, f"mapping rule path {'.'.join(path)!r} "
                                                    f"goes through a non-message field")
                current = self.ros1_spec(f1.base_type)
        assert f1 is not None
        return f1, current.full_name

    def _check_link(self, ros1_name: str, path: str, f1: Ros1Field, f2: Field,
                    in_time: bool = False) -> Optional[MessageMapping]:
        t2 = f2.type

        def fail(why: str) -> NoMappingError:
            return NoMappingError(ros1_name, f"field {path} ({f1.type}) cannot map to "
                                             f"{f2.name} ({t2}): {why}")

        if not f1.is_array:
            if t2.is_array:
                raise fail("an array and a single value")
        elif f1.array_len is None:
            if t2.kind not in (SEQUENCE, BOUNDED):
                raise fail("a variable-length array and a fixed one")
        elif t2.kind != ARRAY or t2.size != f1.array_len:
            raise fail("fixed arrays of different lengths" if t2.kind == ARRAY
                       else "a fixed-length array and a variable one")
        base = f1.base_type
        if base in ROS1_PRIMITIVES:
            same = base == t2.base or (base in ONE_BYTE and t2.base in ONE_BYTE) \
                or ((ros1_name in _TIME_SPECS or in_time)  # uint32 secs <-> int32 sec
                    and t2.base in ("int32", "uint32"))
            if not same:
                raise fail("different primitive types")
            return None
        if base == "string":
            if t2.base != "string":
                raise fail("a string and another type")
            return None
        if base in _TIME_SPECS:
            want = TIME if base == "time" else DURATION
            if t2.base != want:
                raise fail(f"ROS 1 {base} maps to {want}")
            return self.message(base)
        if not t2.is_nested:
            raise fail("a message and a primitive")
        try:
            nested = self.message(base)
        except NoMappingError as exc:
            raise fail(exc.reason) from None
        if nested.ros2_type != t2.base:
            # the nested ROS 1 type maps elsewhere by default: pair it with this one
            try:
                nested = self._pair(base, t2.base, None)
            except NoMappingError as exc:
                raise fail(exc.reason) from None
        return nested

    def _check_order(self, ros1_name: str, spec: MsgSpec, links: Sequence[Link]) -> None:
        """The converters walk the ROS 1 fields in order: the ROS 2 members they feed must
        come in the same order."""
        order: List[int] = []
        paths = {link.ros1_path: i for i, link in enumerate(links) if link.ros1_path}

        def walk(current: MsgSpec, prefix: Tuple[str, ...]) -> None:
            for f1 in current.fields:
                path = prefix + (f1.name,)
                if path in paths:
                    order.append(paths[path])
                elif any(p[:len(path)] == path for p in paths):
                    walk(self.ros1_spec(f1.base_type), path)

        walk(spec, ())
        if order != sorted(order):
            raise NoMappingError(ros1_name, "the mapped fields come in a different order in "
                                            "ROS 1 and ROS 2 (not supported by the byte "
                                            "converters)")

    # -- services and actions ------------------------------------------------------------------
    def service(self, ros1_type: str) -> ServiceMapping:
        """The mapping of ROS 1 service type ``ros1_type``: request and response."""
        name = normalize_type(ros1_type)
        found = self._services.get(name)
        if found is None:
            with self._lock:
                try:
                    found = self._service(name)
                except NoMappingError as exc:
                    found = exc
                self._services[name] = found
        if isinstance(found, NoMappingError):
            raise found
        return found

    def _service(self, name: str) -> ServiceMapping:
        srv = self._base_ros1.get_srv_spec(name)
        package, _, short = name.partition("/")
        rule = self._service_rules.get((package, short))
        candidates: List[Tuple[str, Dict[str, str], Dict[str, str]]] = []
        if rule is not None:
            candidates.append(rule)
        candidates += [(f"{c}/srv/{short}", {}, {}) for c in self._ros2_packages(package)]
        for ros2_name, req_fields, resp_fields in candidates:
            try:
                service = self.ros2.service(ros2_name)
            except UnknownTypeError:
                continue
            request = self._pair(srv.request.full_name, service.request.name, req_fields or None)
            response = self._pair(srv.response.full_name, service.response.name,
                                  resp_fields or None)
            return ServiceMapping(name, service.name, request, response, False)
        if not self.generate:
            raise NoMappingError(name, "no ROS 2 service of that package and name")
        ros2_name = f"{package}/srv/{short}"
        request_type = self._make_ros2(srv.request, f"{ros2_name}_Request")
        response_type = self._make_ros2(srv.response, f"{ros2_name}_Response")
        self.ros2.add(make_service(ros2_name, request_type, response_type,
                                   self.ros2.has_type_hashes, "",
                                   f"made by minros from ROS 1's {name}"))
        request = self._pair(srv.request.full_name, request_type.name, None)
        response = self._pair(srv.response.full_name, response_type.name, None)
        return ServiceMapping(name, ros2_name, request, response, True)

    def action(self, ros1_type: str) -> ActionMapping:
        """The mapping of ROS 1 action ``pkg/Name`` (its Goal, Result and Feedback messages)."""
        name = normalize_type(ros1_type)
        package, _, short = name.partition("/")
        parts = [f"{name}{suffix}" for suffix in ("Goal", "Result", "Feedback")]
        with self._lock:
            specs = [self.ros1_spec(p) for p in parts]
            for candidate in self._ros2_packages(package):
                try:
                    action = self.ros2.action(f"{candidate}/action/{short}")
                except UnknownTypeError:
                    continue
                goal, result, feedback = (self._pair(p, t.name, None) for p, t in
                                          zip(parts, (action.goal, action.result,
                                                      action.feedback)))
                return ActionMapping(name, action.name, goal, result, feedback, False,
                                     list(ACTION_NOTES))
            if not self.generate:
                raise NoMappingError(name, "no ROS 2 action of that package and name")
            ros2_name = f"{package}/action/{short}"
            made = [self._make_ros2(s, f"{ros2_name}_{suffix}")
                    for s, suffix in zip(specs, ("Goal", "Result", "Feedback"))]
            self.ros2.add(make_action(ros2_name, made[0], made[1], made[2],
                                      self.ros2.has_type_hashes, "",
                                      f"made by minros from ROS 1's {name}"))
            goal, result, feedback = (self._pair(p, t.name, None) for p, t in zip(parts, made))
            return ActionMapping(name, ros2_name, goal, result, feedback, True,
                                 list(ACTION_NOTES))

    # -- ROS 2 -> ROS 1 --------------------------------------------------------------------------
    def ros1_type_for(self, ros2_type: str) -> str:
        """The ROS 1 type whose mapping is ROS 2 type ``ros2_type`` (``pkg/msg/Name``): by the
        rules above read backwards; raises :class:`NoMappingError` when none is known."""
        from .model import split_type_name

        package, ns, short = split_type_name(ros2_type)
        full = f"{package}/{ns}/{short}"
        candidates: List[str] = []
        if full == TIME:
            candidates.append("std_msgs/Time")
        elif full == DURATION:
            candidates.append("std_msgs/Duration")
        for (p1, m1), (target, _fields) in self._message_rules.items():
            if target == full:
                candidates.append(f"{p1}/{m1}")
        packages = [package]
        if package.endswith("_interfaces"):
            packages.append(package[:-len("_interfaces")] + "_msgs")
        packages += [p1 for p1, targets in self._package_rules.items() if package in targets]
        candidates += [f"{p}/{short}" for p in packages]
        for candidate in candidates:
            try:
                self.ros1_spec(candidate)
                if self.message(candidate).ros2_type == full:
                    return candidate
            except (UnknownTypeError, NoMappingError, MsgSpecError):
                continue
        raise NoMappingError(full, "no ROS 1 type maps to it (no ROS 1 package of that name "
                                   "has the type, and no mapping rule names it)")

    def message_from_ros2(self, ros2_type: str) -> MessageMapping:
        """The mapping for ROS 2 message type ``ros2_type``, seen from ROS 2: its ROS 1
        counterpart (:meth:`ros1_type_for`), or, when none exists, a ROS 1 type made from the
        ROS 2 definition (``pkg/Name``: ``builtin_interfaces`` Time/Duration become
        ``time``/``duration``, ``std_msgs/Header`` ``Header``, bounds are dropped, nested types
        become their ROS 1 counterparts; a ``wstring`` cannot map). The made type is added to
        this mapper's ROS 1 types, md5 sum and message_definition included."""
        from .model import split_type_name

        try:
            return self.message(self.ros1_type_for(ros2_type))
        except NoMappingError:
            pass
        package, ns, short = split_type_name(ros2_type)
        if ns != "msg":
            raise NoMappingError(ros2_type, "only messages (pkg/msg/Name) get ROS 1 types made")
        with self._lock:
            name = f"{package}/{short}"
            self._own_ros1.add_spec(parse_msg(self._ros1_text(f"{package}/msg/{short}"), name,
                                              f"made by minros from ROS 2's {ros2_type}"))
            self._forget()
            mapping = self.message(name)
            if mapping.ros2_type != f"{package}/msg/{short}":
                raise NoMappingError(ros2_type, f"the ROS 1 type made for it maps to "
                                                f"{mapping.ros2_type}")
            return mapping

    def _ros1_text(self, ros2_type: str) -> str:
        struct = self.ros2.message(ros2_type)
        lines = []
        for c in struct.constants:
            value = ("1" if c.value else "0") if c.type == "bool" else str(c.value)
            lines.append(f"{c.type} {c.name}={value}")
        for f in struct.fields:
            if f.name == EMPTY_MEMBER and struct.is_empty:
                continue
            t = f.type
            if t.base == "wstring":
                raise NoMappingError(ros2_type, f"field {f.name} is a wstring, which ROS 1 "
                                                f"has no type for")
            if t.base == TIME:
                base = "time"
            elif t.base == DURATION:
                base = "duration"
            elif t.is_nested:
                base = self.message_from_ros2(t.base).ros1_type
                if base == "std_msgs/Header":
                    base = "Header"
            else:
                base = t.base
            suffix = "" if not t.is_array else f"[{t.size}]" if t.kind == ARRAY else "[]"
            lines.append(f"{base}{suffix} {f.name}")
        return "\n".join(lines) + ("\n" if lines else "")


def ros2_msg_text(fields: Sequence[Field], constants: Sequence[Constant]) -> str:
    """A ROS 2 ``.msg`` text for fields and constants (what rosidl would read them as).

    String constants containing ``#`` are left out: ROS 2 reads ``#`` as a comment anywhere."""
    lines = []
    for c in constants:
        if c.type == "string":
            if "#" in str(c.value):
                continue
            value = '"' + str(c.value).replace('"', '\\"') + '"'
        elif c.type == "bool":
            value = "true" if c.value else "false"
        else:
            value = repr(c.value)
        lines.append(f"{c.type} {c.name}={value}")
    lines += [f"{f.type.msg_text()} {f.name}" for f in fields
              if not (f.name == EMPTY_MEMBER and len(fields) == 1)]
    return "\n".join(lines) + ("\n" if lines else "")


def _load_yaml(path: Path) -> List[Dict[str, Any]]:
    import yaml

    data = yaml.safe_load(path.read_text(encoding="utf-8"))
    if not isinstance(data, list):
        raise MsgSpecError("a ros1_bridge mapping rules file holds a list of rules", str(path))
    return data


_mappers: Dict[str, Mapper] = {}
_mappers_lock = threading.Lock()


def mapper(distro: str = "jazzy") -> Mapper:
    """A shared :class:`Mapper` over minros's installed ROS 1 types and ``distro``'s ROS 2 ones."""
    with _mappers_lock:
        found = _mappers.get(distro)
        if found is None:
            found = _mappers[distro] = Mapper(distro)
        return found


def ros2_type_for(ros1_type: str, distro: str = "jazzy") -> str:
    """The ROS 2 type (``pkg/msg/Name``) ROS 1 type ``ros1_type`` maps to (made if need be)."""
    return mapper(distro).ros2_type_for(ros1_type)
