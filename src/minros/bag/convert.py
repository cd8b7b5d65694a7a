"""``rosbag convert``: ROS 1 bags to ROS 2 recordings (rosbag2) and back.

To ROS 2: every topic's ROS 1 type is mapped by ros1_bridge's rules (:mod:`minros.ros2.types`:
field names lower-cased, Header without ``seq``, ``time`` -> ``builtin_interfaces/Time``), or,
for a type ROS 2 has no counterpart of, a ROS 2 type is made from the bag's own definition; the
messages go through the generated ROS 1 -> CDR converters, bytes to bytes. The bag's
definitions are what its bytes mean, so they are used even when minros has a type of that name.
The rosbag2 directory gets metadata version 9 with each topic's type hash (Humble: version 5,
no hashes), rosbag2's ``ros2msg`` definitions, transient local QoS for latched topics, and,
in ``custom_data``, the ROS 1 types, so converting back restores them exactly.

To ROS 1: a rosbag2 directory or ROS 2 MCAP/SQLite file is read through
:class:`minros.bag.ros2.reader.Rosbag2Reader` and written as a bag (or ROS 1 MCAP).

A topic that cannot be converted is named with the reason and left out; the rest goes on.
"""

from __future__ import annotations

import fnmatch
import os
import shutil
import sys
from dataclasses import dataclass, field
from typing import Any, Callable, Dict, List, Optional, TextIO, Tuple

from minros.bag.bag import open_reader, open_writer
from minros.bag.errors import ROSBagException, ROSBagUnindexedException
from minros.bag.progress import ProgressMeter
from minros.bag.ros2 import msgdef
from minros.bag.ros2.reader import ROS1_KEY, Rosbag2Reader, stash
from minros.bag.ros2.storage import kind as ros2_kind
from minros.bag.ros2.writer import Rosbag2Writer, latch_qos


@dataclass
class Selection:
    """``--topic`` / ``--exclude``: each a topic name or a message type (ROS 1 or ROS 2
    spelling), shell wildcards allowed. No ``--topic``: every topic."""

    topics: List[str] = field(default_factory=list)
    exclude: List[str] = field(default_factory=list)

    @staticmethod
    def _match(patterns: List[str], names: Tuple[str, ...]) -> bool:
        return any(fnmatch.fnmatchcase(n, p) or fnmatch.fnmatchcase(n, "/" + p.lstrip("/"))
                   for p in patterns for n in names if n)

    def wants(self, topic: str, *types: str) -> bool:
        names = (topic, *types)
        if self.topics and not self._match(self.topics, names):
            return False
        return not self._match(self.exclude, names)


@dataclass
class Plan:
    """One converted topic."""

    topic: str
    source_type: str
    target_type: str
    notes: List[str]
    convert: Callable[..., bytes]
    target: Any  # the output connection
    errors: int = 0
    first_error: str = ""
    written: int = 0


@dataclass
class Result:
    path: str
    plans: Dict[int, Plan]
    skipped: Dict[str, Tuple[str, str]]


class Reporter:
    """What convert prints: the plan on ``out``, warnings on ``err``."""

    def __init__(self, out: TextIO, err: TextIO, quiet: bool) -> None:
        self.out, self.err, self.quiet = out, err, quiet

    def plan(self, plans: Dict[int, Plan]) -> None:
        if self.quiet or not plans:
            return
        seen: Dict[str, Plan] = {}
        for p in plans.values():
            seen.setdefault(p.topic, p)
        width = max(len(t) for t in seen)
        twidth = max(len(p.source_type) for p in seen.values())
        for topic, p in sorted(seen.items()):
            notes = f"  ({'; '.join(p.notes)})" if p.notes else ""
            print(f"  {topic:<{width}}  {p.source_type:<{twidth}} -> {p.target_type}{notes}",
                  file=self.out)
        self.out.flush()

    def warn(self, text: str) -> None:
        self.out.flush()
        print(f"WARNING: {text}", file=self.err)
        self.err.flush()


def _skip_note(topic: str) -> str:
    return f"(leave it out with --exclude {topic})"


# ---------------------------------------------------------------------------------------------
# ROS 1 -> ROS 2

def to_ros2(src: str, dst: str, storage: str = "mcap", distro: str = "jazzy",
            selection: Optional[Selection] = None, quiet: bool = False,
            out: Optional[TextIO] = None, err: Optional[TextIO] = None) -> Result:
    """Convert ROS 1 bag (or ROS 1 MCAP) ``src`` into the new rosbag2 directory ``dst``."""
    from minros.ros2.types import Mapper

    selection = selection or Selection()
    report = Reporter(out or sys.stdout, err or sys.stderr, quiet)
    if ros2_kind(src):
        raise ROSBagException(f"{src} is a ROS 2 recording already: convert it with --to ros1")
    reader = open_reader(src, allow_unindexed=False)
    try:
        mapper = Mapper(distro)
        has_hashes = mapper.ros2.has_type_hashes
        problems: Dict[str, Tuple[str, str]] = {}
        everything = list(reader.connections.values())
        # the bag's definitions first (a mapping made before a definition is added would not
        # see it); a type with two different definitions in one bag cannot be one ROS 2 type
        first: Dict[str, str] = {}
        for c in everything:
            if c.datatype in first:
                if c.md5sum != first[c.datatype] and c.md5sum not in ("", "*"):
                    problems[c.topic] = (c.datatype, (
                        f"a second definition of {c.datatype} (md5 {c.md5sum}; another topic has "
                        f"{first[c.datatype]}): a ROS 2 recording holds one definition per type, "
                        f"so convert this topic on its own with --topic {c.topic}"))
                continue
            first[c.datatype] = c.md5sum
            if c.msg_def:
                try:
                    mapper.add_ros1_definition(c.datatype, c.msg_def)
                except Exception as exc:  # noqa: BLE001 - a damaged definition: that topic only
                    problems[c.topic] = (c.datatype, f"its message definition in the bag does not "
                                                     f"parse: {_line(exc)}")
        conns = [c for c in everything
                 if selection.wants(c.topic, c.datatype, _ros2_name(mapper, c.datatype))]
        skipped = {c.topic: problems[c.topic] for c in conns if c.topic in problems}
        writer = Rosbag2Writer(dst, storage, distro)
        try:
            plans: Dict[int, Plan] = {}
            targets: Dict[Tuple[str, str, bool], Any] = {}
            stash_topics: Dict[str, Dict[str, Any]] = {}
            stash_types: Dict[str, Dict[str, str]] = {}
            for c in conns:
                if c.topic in skipped:
                    continue
                try:
                    m = mapper.message(c.datatype)
                    ctx = mapper.ros1_context
                    if not c.msg_def and c.md5sum not in ("", "*") \
                            and ctx.md5sum(c.datatype) != c.md5sum:
                        raise ValueError(f"the bag stores no definition, and the installed "
                                         f"{c.datatype} has md5 {ctx.md5sum(c.datatype)}, not "
                                         f"the bag's {c.md5sum}")
                    convert = m.transcoder.ros1_to_cdr
                    definition = msgdef.full_text(mapper.ros2, m.ros2_type)
                    type_hash = m.type_hash if has_hashes else ""
                except Exception as exc:  # noqa: BLE001 - NoMappingError, unknown types, ...
                    skipped[c.topic] = (c.datatype, _reason(exc))
                    continue
                latching = c.latching == "1"
                key = (c.topic, m.ros2_type, latching)
                target = targets.get(key)
                if target is None:
                    target = targets[key] = writer.add_topic(
                        c.topic, m.ros2_type, definition, type_hash,
                        latch_qos() if latching else [])
                notes = [f"without {f}" for f in m.all_dropped()]
                notes += [f"{f} at its default" for f in m.all_defaulted()]
                if m.generated:
                    notes.append("ROS 2 type made from the bag's definition")
                plans[c.id] = Plan(c.topic, c.datatype, m.ros2_type, notes, convert, target)
                stash_topics.setdefault(c.topic, {
                    "type": c.datatype, "ros2_type": m.ros2_type, "callerid": c.callerid,
                    "latching": c.latching})
                if c.datatype not in stash_types:
                    stash_types[c.datatype] = _ros1_stash(c, ctx)
            for topic, (datatype, reason) in sorted(skipped.items()):
                report.warn(f"{topic} [{datatype}] is not converted: {reason} "
                            f"{_skip_note(topic)}")
            if stash_topics:
                writer.custom_data[ROS1_KEY] = stash(stash_topics, stash_types)
            report.plan(plans)
            _copy(reader.messages(list(plans), None, None), plans, writer.write, dst,
                  _ros1_size(reader), report)
            writer.close()
        except BaseException:
            writer.abort()
            raise
    finally:
        reader.close()
    _errors(plans, report)
    return Result(dst, plans, skipped)


def _ros2_name(mapper: Any, ros1_type: str) -> str:
    """The ROS 2 type ``ros1_type`` maps to ('' if none: selection by ROS 2 name then fails)."""
    try:
        return str(mapper.message(ros1_type).ros2_type)
    except Exception:  # noqa: BLE001 - named later, when the topic is converted
        return ""


def _ros1_stash(c: Any, ctx: Any) -> Dict[str, str]:
    """What converting back needs to restore ``c``'s type: its md5 sum, and its definition
    unless minros has the type installed with that md5 sum (most types: metadata.yaml stays
    small)."""
    from minros.msgs import REGISTRY

    md5 = c.md5sum if c.md5sum not in ("", "*") else ctx.md5sum(c.datatype)
    try:
        installed = REGISTRY.md5sum(c.datatype)
    except Exception:  # noqa: BLE001 - not installed, or its installed definition is broken
        installed = None
    if installed == md5:
        return {"md5sum": md5}
    return {"md5sum": md5, "message_definition": c.msg_def or ctx.full_text(c.datatype)}


def _ros1_size(reader: Any) -> int:
    chunks = getattr(reader, "chunks", None) or []
    total = sum(c.uncompressed_size for c in chunks)
    return total or 1


def _copy(messages: Any, plans: Dict[int, Plan], write: Callable[[Any, int, Any], None],
          dst: str, total: int, report: Reporter) -> None:
    meter = None if report.quiet else ProgressMeter(dst, total, out=report.out)
    done = 0
    step = 0
    for cid, t, data, _pos in messages:
        plan = plans[cid]
        try:
            converted = plan.convert(data)
        except Exception as exc:  # noqa: BLE001 - one damaged message: counted, the rest goes on
            plan.errors += 1
            if not plan.first_error:
                plan.first_error = f"at {t // 1_000_000_000}.{t % 1_000_000_000:09d}: {_line(exc)}"
            continue
        write(plan.target, t, converted)
        plan.written += 1
        if meter is not None:
            done += len(data)
            step += 1
            if step >= 64 or len(data) > 65536:
                meter.step(min(done, total))
                step = 0
    if meter is not None:
        meter.finish()


def _errors(plans: Dict[int, Plan], report: Reporter) -> None:
    for p in plans.values():
        if p.errors:
            report.warn(f"{p.errors} message(s) of {p.topic} [{p.source_type}] did not convert "
                        f"and were left out (the first {p.first_error})")


# ---------------------------------------------------------------------------------------------
# ROS 2 -> ROS 1

def to_ros1(src: str, dst: str, distro: Optional[str] = None,
            selection: Optional[Selection] = None, quiet: bool = False,
            out: Optional[TextIO] = None, err: Optional[TextIO] = None) -> Result:
    """Convert rosbag2 recording ``src`` into the new ROS 1 bag ``dst`` (.bag, or .mcap for a
    ROS 1 MCAP file)."""
    selection = selection or Selection()
    report = Reporter(out or sys.stdout, err or sys.stderr, quiet)
    if not ros2_kind(src):
        raise ROSBagException(f"{src} is not a ROS 2 recording (a rosbag2 directory, a ROS 2 "
                              f".mcap or a .db3 file): convert a ROS 1 bag with --to ros2")
    reader = Rosbag2Reader(src, distro=distro)
    try:
        for note in reader.warnings:
            report.warn(note)
        skipped = {t: v for t, v in reader.skipped.items() if selection.wants(t, v[0])}
        for topic, (ros2_type, reason) in sorted(skipped.items()):
            report.warn(f"{topic} [{ros2_type}] is not converted: {reason} {_skip_note(topic)}")
        writer = open_writer(dst, "none", 768 * 1024)
        try:
            plans: Dict[int, Plan] = {}
            for cid, entry in reader.topics.items():
                c = entry.conn
                if not selection.wants(c.topic, c.datatype, entry.ros2_type):
                    continue
                m = entry.mapping
                notes = []
                if m.ros1.has_header:
                    notes.append("header.seq counted from 1")
                notes += [f"{f} zero" for f in m.all_dropped() if f != "header.seq"]
                notes += [f"without {f}" for f in m.all_defaulted()]
                target = writer.connection(c.topic, c.datatype, c.md5sum, c.msg_def, c.callerid,
                                           c.latching)
                plans[cid] = Plan(c.topic, entry.ros2_type, c.datatype, notes, _same, target)
            report.plan(plans)
            def failed(cid: int, t: int, exc: Exception) -> None:
                plan = plans[cid]
                plan.errors += 1
                if not plan.first_error:
                    plan.first_error = f"at {t // 1_000_000_000}.{t % 1_000_000_000:09d}: " \
                                       f"{_line(exc)}"

            _copy(reader.messages(list(plans), None, None, on_error=failed), plans,
                  writer.write, dst, max(reader.size, 1), report)
            writer.close()
        except BaseException:
            writer.abort()
            _remove(dst)
            raise
    finally:
        reader.close()
    _errors(plans, report)
    return Result(dst, plans, skipped)


def _same(data: Any) -> Any:
    return data


def _replaceable(path: str) -> bool:
    """Whether directory ``path`` holds only what a rosbag2 recording does (--force may go)."""
    try:
        names = os.listdir(path)
    except OSError:
        return False
    return all(n == "metadata.yaml" or n.endswith((".mcap", ".db3", ".db3-journal", ".zstd"))
               for n in names)


def _remove(path: str) -> None:
    try:
        if os.path.isdir(path):
            shutil.rmtree(path)
        elif os.path.exists(path):
            os.remove(path)
    except OSError:
        pass


# ---------------------------------------------------------------------------------------------

def convert(src: str, dst: str, to: Optional[str] = None, storage: str = "mcap",
            distro: Optional[str] = None, topics: Optional[List[str]] = None,
            exclude: Optional[List[str]] = None, quiet: bool = False, force: bool = False,
            out: Optional[TextIO] = None, err: Optional[TextIO] = None) -> int:
    """``rosbag convert``: returns the exit status, having printed what went wrong."""
    out = out or sys.stdout
    err = err or sys.stderr

    def fail(text: str) -> int:
        out.flush()
        print(text, file=err)
        return 1

    if not os.path.exists(src):
        return fail(f"ERROR reading {src}: no such file or directory")
    to = to or ("ros1" if ros2_kind(src) else "ros2")
    if os.path.exists(dst):
        if os.path.realpath(dst) == os.path.realpath(src):
            return fail(f"ERROR: the output {dst} is the input")
        if not force:
            return fail(f"ERROR: {dst} exists already: remove it, give another output name, "
                        f"or pass --force to replace it")
        if os.path.isdir(dst) and not _replaceable(dst):
            return fail(f"ERROR: {dst} is a directory that is not a ROS 2 recording: --force "
                        f"replaces only recordings (remove it yourself, or give another name)")
        _remove(dst)
    if to == "ros1" and not (dst.endswith(".bag") or dst.endswith(".mcap")):
        return fail(f"ERROR: the ROS 1 output {dst} must end in .bag (or .mcap for ROS 1 MCAP)")
    selection = Selection(list(topics or []), list(exclude or []))
    try:
        if to == "ros2":
            result = to_ros2(src, dst, storage, distro or "jazzy", selection, quiet, out, err)
            what = f"ROS 2 {distro or 'jazzy'}, {storage}"
        else:
            result = to_ros1(src, dst, distro, selection, quiet, out, err)
            what = "ROS 1"
    except ROSBagUnindexedException:
        return fail(f"ERROR bag unindexed: {src}.  Run rosbag reindex.")
    except ROSBagException as exc:
        return fail(f"ERROR reading {src}: {exc}" if not str(exc).startswith(dst)
                    else f"ERROR writing {dst}: {exc}")
    except OSError as exc:
        return fail(f"ERROR writing {dst}: {exc.strerror or exc}")
    if not result.plans:
        _remove(dst)
        return fail(f"ERROR: no topic of {src} could be converted"
                    if result.skipped else f"ERROR: no topic of {src} is selected")
    if not quiet:
        messages = sum(p.written for p in result.plans.values())
        topics_n = len({p.topic for p in result.plans.values()})
        print(f"Wrote {dst} ({what}): {messages} messages on {topics_n} topics", file=out)
    return 0


def _reason(exc: BaseException) -> str:
    from minros.ros2.types import NoMappingError

    if isinstance(exc, NoMappingError):
        return exc.reason
    return _line(exc)


def _line(exc: BaseException) -> str:
    text = str(exc).strip()
    return text.splitlines()[0] if text else type(exc).__name__
