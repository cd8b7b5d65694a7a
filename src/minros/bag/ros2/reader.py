"""A rosbag2 recording seen as a ROS 1 bag: ROS 1 types, md5 sums, definitions and bytes.

This is the reader ``rosbag info``, ``rosbag play``, ``rostopic echo -b``, the ``Bag`` API and
``rosbag convert --to ros1`` use for rosbag2 directories and ROS 2 MCAP or SQLite files: the
same interface as :mod:`minros.bag.bag1`'s reader, each message converted from CDR to ROS 1
bytes as it is read (:mod:`minros.ros2.types`' generated converters, bytes to bytes).

Which ROS 1 type a topic gets, first that applies:

1. the ROS 1 type minros wrote into the recording when it made it from a ROS 1 bag
   (``custom_data`` ``minros.ros1``: type, md5 sum, definition, callerid, latching per topic),
   so a bag converted to ROS 2 and back has its own types again;
2. the ROS 1 counterpart of the ROS 2 type by ros1_bridge's rules (``sensor_msgs/msg/Image``
   -> ``sensor_msgs/Image``);
3. a ROS 1 type made from the ROS 2 definition (the recording's own, when minros does not
   know the type or the recording's type hash differs from minros's).

Header ``seq`` is ROS 2-less: it is counted per topic from 1 on every read. A topic that cannot
be converted (no definition, a ``wstring``, an IDL definition ...) is left out and listed in
``skipped`` with the reason; the others read all the same.
"""

from __future__ import annotations

import json
from typing import Any, Callable, Dict, Iterator, List, Optional, Tuple

from minros.bag.bag1 import ConnInfo
from minros.bag.errors import ROSBagFormatException
from minros.bag.ros2 import msgdef
from minros.bag.ros2.storage import Rosbag2
from minros.ros2.types import DISTROS, Mapper, NoMappingError

#: the custom_data key under which minros keeps each topic's ROS 1 type (a JSON object)
ROS1_KEY = "minros.ros1"


def stash(topics: Dict[str, Dict[str, Any]], types: Dict[str, Dict[str, str]]) -> str:
    """The custom_data value of :data:`ROS1_KEY`: ``topics`` maps each topic to its ROS 1
    ``type``, ``ros2_type``, ``callerid`` and ``latching``; ``types`` each ROS 1 type to its
    ``md5sum`` and ``message_definition``."""
    return json.dumps({"types": types, "topics": topics}, sort_keys=True)


def latched(qos_profiles: List[Any]) -> bool:
    """Whether a topic's offered QoS is transient local (ROS 2's latching)."""
    return any(getattr(q.durability, "name", "") == "TRANSIENT_LOCAL" for q in qos_profiles)


def reading_distro(store: Rosbag2, requested: Optional[str] = None) -> str:
    """The ROS 2 distro whose types read the recording: asked for, else the one its metadata
    names, else Humble for a recording without type hashes (Humble wrote none), else Jazzy."""
    if requested:
        return requested
    if store.ros_distro in DISTROS:
        return str(store.ros_distro)
    if store.metadata is not None and store.connections \
            and not any(c.digest for c in store.connections):
        return "humble"
    return "jazzy"


class Topic:
    """How one rosbag2 topic reads as ROS 1."""

    def __init__(self, conn: ConnInfo, ros2_type: str, type_hash: str, mapping: Any) -> None:
        self.conn = conn
        self.ros2_type = ros2_type
        self.type_hash = type_hash
        self.mapping = mapping
        self.to_ros1: Callable[..., bytes] = mapping.transcoder.cdr_to_ros1


class Rosbag2Reader:
    """A rosbag2 recording opened for reading as ROS 1 (see the module docstring)."""

    indexed = True
    index_loaded = True

    def __init__(self, path: str, allow_unindexed: bool = False,
                 distro: Optional[str] = None) -> None:
        self.path = path
        self.store = Rosbag2(path)
        try:
            self.distro = reading_distro(self.store, distro)
            self.mapper = Mapper(self.distro)
            #: topic -> (ROS 2 type, reason) of the topics that do not read as ROS 1
            self.skipped: Dict[str, Tuple[str, str]] = {}
            #: notes on topics that read, but not quite as recorded (a type hash that differs)
            self.warnings: List[str] = []
            self.topics: Dict[int, Topic] = {}
            self._plan()
        except BaseException:
            self.store.close()
            raise
        self.connections: Dict[int, ConnInfo] = {cid: t.conn for cid, t in self.topics.items()}
        self.counts: Dict[int, int] = {c.id: c.msgcount for c in self.store.connections
                                       if c.id in self.topics}
        self.chunks: List[Any] = []
        self._by_id = {c.id: c for c in self.store.connections}

    # -- what each topic becomes -------------------------------------------------------------

    @property
    def version(self) -> str:
        s = self.store
        what = f"rosbag2 {s.version}" if s.version is not None else "rosbag2 storage file"
        return f"{what} ({s.storage_id}, cdr; read as ROS 2 {self.distro})"

    @property
    def size(self) -> int:
        return self.store.size

    def _stash(self) -> Dict[str, Dict[str, Any]]:
        """topic -> {type, md5sum, message_definition, ros2_type, callerid, latching} of the
        ROS 1 topics minros converted this recording from (custom_data, see :func:`stash`)."""
        text = self.store.custom_data.get(ROS1_KEY)
        if not text:
            return {}
        try:
            data = json.loads(text)
            types, topics = data["types"], data["topics"]
            return {topic: {**entry, **types[entry["type"]]} for topic, entry in topics.items()}
        except (ValueError, KeyError, TypeError, AttributeError):
            self.warnings.append(f"custom_data {ROS1_KEY} is damaged: the ROS 1 types minros "
                                 f"stored are ignored")
            return {}

    def _plan(self) -> None:
        stash = self._stash()
        reg = self.mapper.ros2
        # first every definition the recording brings (a mapping made before one is added
        # would not see it), then each topic's mapping
        own: Dict[int, Dict[str, str]] = {}
        for c in self.store.connections:
            ros1 = stash.get(c.topic)
            if isinstance(ros1, dict) and ros1.get("ros2_type") == c.msgtype:
                try:
                    if ros1.get("message_definition"):
                        self.mapper.add_ros1_definition(ros1["type"], ros1["message_definition"])
                    own[c.id] = ros1
                except Exception:  # noqa: BLE001, S110 - a damaged stash: the ROS 2 rules decide
                    pass
        for c in self.store.connections:
            try:
                self._add_ros2_definitions(reg, c)
            except Exception as exc:  # noqa: BLE001 - a definition that does not read: named
                self.skipped[c.topic] = (c.msgtype, _reason(exc))
        for c in self.store.connections:
            if c.topic in self.skipped:
                continue
            try:
                self.topics[c.id] = self._topic(c, own.get(c.id))
            except Exception as exc:  # noqa: BLE001 - any type that does not map: named, left out
                self.skipped[c.topic] = (c.msgtype, _reason(exc))

    def _add_ros2_definitions(self, reg: Any, c: Any) -> None:
        """Add the recording's definition of ``c``'s type where minros lacks it or the
        recording's type hash says its type differs from minros's."""
        name = c.msgtype
        if len(name.split("/")) != 3:
            raise ValueError(f"{name!r} is not a ROS 2 type name (pkg/msg/Name)")
        known = reg.has(name)
        differs = False
        if known and c.digest and reg.has_type_hashes:
            differs = reg.type_hash(name) != c.digest
        if known and not differs:
            return
        if c.msgdef.data and getattr(c.msgdef.format, "name", "") == "IDL":
            raise msgdef.DefinitionError("its stored definition is IDL, which minros does not "
                                         "read (only .msg definitions, encoding ros2msg)")
        if not c.msgdef.data:
            if not known:
                raise msgdef.DefinitionError(
                    f"minros has no ROS 2 {self.distro} type {name} and the recording stores "
                    f"no definition of it")
            self.warnings.append(f"{c.topic}: the recording's {name} has type hash {c.digest}, "
                                 f"minros's {self.distro} one {reg.type_hash(name)}, and the "
                                 f"recording stores no definition: read as minros's")
            return
        for block, text in msgdef.split(name, c.msgdef.data):
            if differs or not reg.has(block):
                reg.add_definition("msg", block, text, origin=f"<{self.path}: {name}>")

    def _topic(self, c: Any, ros1: Optional[Dict[str, str]]) -> Topic:
        mapper = self.mapper
        mapping = None
        if ros1 is not None:
            found = mapper.message(ros1["type"])
            if found.ros2_type == c.msgtype:
                mapping = found
        if mapping is None:
            ros1 = None
            mapping = mapper.message_from_ros2(c.msgtype)
        ctx = mapper.ros1_context
        ros1_type = mapping.ros1_type
        if ros1 is not None:
            md5 = ros1.get("md5sum") or ctx.md5sum(ros1_type)
            # no definition stored: minros has the type installed with that md5 sum, whose
            # text is the one to give (the recording's other definitions may spell a nested
            # type, Header say, with other comments)
            text = ros1.get("message_definition") or _installed_text(ros1_type, md5) \
                or ctx.full_text(ros1_type)
            callerid, latching = ros1.get("callerid"), ros1.get("latching")
        else:
            md5, text = ctx.md5sum(ros1_type), ctx.full_text(ros1_type)
            callerid, latching = None, "1" if latched(c.ext.offered_qos_profiles) else None
        type_hash = c.digest
        if not type_hash and mapper.ros2.has_type_hashes:
            type_hash = mapping.type_hash
        conn = ConnInfo(c.id, c.topic, ros1_type, md5, text, callerid, latching)
        return Topic(conn, c.msgtype, type_hash, mapping)

    # -- the reader interface of minros.bag ----------------------------------------------------

    def time_range(self) -> Optional[Tuple[int, int]]:
        if not any(self.counts.values()):
            return None
        return self.store.time_range

    def index_times(self, conn_ids: List[int]) -> List[int]:
        conns = [self._by_id[c] for c in conn_ids if c in self.topics]
        return [t for _c, t, _d in self.store.messages(conns)]

    def messages(self, conn_ids: Optional[List[int]], start: Optional[int],
                 end: Optional[int],
                 on_error: Optional[Callable[[int, int, Exception], None]] = None,
                 ) -> Iterator[Tuple[int, int, bytes, Tuple[int, int]]]:
        """(connection id, time ns, ROS 1 bytes, (0, 0)) in time order, times inclusive.
        A message that does not convert raises :class:`ROSBagFormatException`, or, given
        ``on_error``, is reported to it and left out."""
        ids = list(self.topics) if conn_ids is None else [c for c in conn_ids if c in self.topics]
        conns = [self._by_id[c] for c in ids]
        seqs = dict.fromkeys(ids, 0)
        topics = self.topics
        stop = None if end is None else end + 1
        for rconn, t, data in self.store.messages(conns, start, stop):
            cid = rconn.id
            seq = seqs[cid] + 1
            seqs[cid] = seq
            try:
                out = topics[cid].to_ros1(data, seq)
            except Exception as exc:  # noqa: BLE001 - what a damaged message makes a converter raise
                if on_error is not None:
                    on_error(cid, t, exc)
                    continue
                topic = topics[cid]
                raise ROSBagFormatException(
                    f"the {topic.ros2_type} message of {topic.conn.topic} at "
                    f"{t // 1_000_000_000}.{t % 1_000_000_000:09d} does not convert to "
                    f"{topic.conn.datatype}: {_reason(exc)}") from None
            yield cid, t, out, (0, 0)

    def raw_messages(self, conn_ids: Optional[List[int]] = None) -> Iterator[Tuple[int, int, bytes]]:
        """(connection id, time ns, CDR bytes) as stored."""
        ids = list(self.topics) if conn_ids is None else conn_ids
        for rconn, t, data in self.store.messages([self._by_id[c] for c in ids]):
            yield rconn.id, t, data

    def info_rows(self) -> List[Tuple[str, str]]:
        """What ``rosbag info`` adds for a rosbag2 recording: each topic's ROS 2 type and hash,
        and the topics that do not read as ROS 1."""
        rows: List[Tuple[str, str]] = []
        seen: Dict[str, str] = {}
        for t in self.topics.values():
            seen.setdefault(t.ros2_type, t.type_hash)
        width = max((len(n) for n in seen), default=0)
        for i, (name, digest) in enumerate(sorted(seen.items())):
            rows.append(("ros2 types" if i == 0 else "",
                         f"{name:<{width}} [{digest}]" if digest else name))
        for i, (topic, (ros2_type, reason)) in enumerate(sorted(self.skipped.items())):
            rows.append(("skipped" if i == 0 else "", f"{topic} : {ros2_type} ({reason})"))
        return rows

    def close(self) -> None:
        self.store.close()


def _installed_text(ros1_type: str, md5: str) -> str:
    from minros.msgs import REGISTRY

    try:
        return REGISTRY.full_text(ros1_type) if REGISTRY.md5sum(ros1_type) == md5 else ""
    except Exception:  # noqa: BLE001 - not installed, or its installed definition is broken
        return ""


def _reason(exc: BaseException) -> str:
    if isinstance(exc, NoMappingError):
        return exc.reason
    text = str(exc).strip()
    return text.splitlines()[0] if text else type(exc).__name__
