"""``rosbag info``: the summary of a bag in rosbag's two layouts (aligned text and YAML)."""
# ruff: noqa: UP031 - printf widths (%-*s, %*d) are the clearest way to state rosbag's column layout

from __future__ import annotations

import json
import sys
import time
from typing import Any, Dict, List, Optional, Tuple

from minros.bag.errors import Compression


def human_size(size: float) -> str:
    for suffix in ("KB", "MB", "GB", "TB", "PB", "EB", "ZB", "YB"):
        size /= 1024.0
        if size < 1024.0:
            return f"{size:.1f} {suffix}"
    return "-"


def human_frequency(freq: float) -> str:
    for suffix in ("Hz", "kHz", "MHz", "GHz", "THz", "PHz", "EHz", "ZHz", "YHz"):
        if freq < 1000.0:
            return f"{freq:.1f} {suffix}"
        freq /= 1000.0
    return "-"


def time_to_str(secs: float) -> str:
    frac = ("%.2f" % (secs - int(secs)))[1:]
    return time.strftime("%b %d %Y %H:%M:%S", time.localtime(secs)) + frac


def duration_str(duration: float) -> str:
    secs = duration % 60
    mins = int(duration / 60)
    hrs = int(mins / 60)
    if hrs > 0:
        return "%dhr %d:%02ds (%ds)" % (hrs, mins % 60, secs, duration)
    if mins > 0:
        return "%d:%02ds (%ds)" % (mins, secs, duration)
    return "%.1fs" % duration


def _version_str(bag: Any) -> str:
    version = bag.version
    if version == "mcap":
        return "mcap (ros1 profile)"
    if isinstance(version, str):  # a ROS 2 recording: what its reader says it is
        return version
    return "%d.%d" % (int(version / 100), version % 100)


def _compression_stats(bag: Any) -> Tuple[Dict[str, int], Dict[str, int], Dict[str, int], int]:
    counts: Dict[str, int] = {}
    unc: Dict[str, int] = {}
    comp: Dict[str, int] = {}
    chunks = bag._chunk_summaries()
    for c in chunks:
        counts[c.compression] = counts.get(c.compression, 0) + 1
        unc[c.compression] = unc.get(c.compression, 0) + c.uncompressed_size
        comp[c.compression] = comp.get(c.compression, 0) + c.compressed_size
    return counts, unc, comp, len(chunks)


def info_text(bag: Any, with_freq: bool = False) -> str:
    rows: List[Tuple[str, str]] = [("path", bag.filename)] if bag.filename else []  # a file object has none
    rows.append(("version", _version_str(bag)))
    rng = bag._time_range()
    if rng is None:
        rows.append(("size", human_size(bag.size)))
    else:
        start, end = rng[0] / 1e9, rng[1] / 1e9
        duration = end - start
        rows.append(("duration", duration_str(duration)))
        rows.append(("start", "%s (%.2f)" % (time_to_str(start), start)))
        rows.append(("end", "%s (%.2f)" % (time_to_str(end), end)))
        rows.append(("size", human_size(bag.size)))
        rows.append(("messages", str(bag.get_message_count())))
        counts, unc, comp, n = _compression_stats(bag)
        if not counts:
            rows.append(("compression", "none"))
        else:
            parts = []
            for count, name in sorted(((v, k) for k, v in counts.items()), reverse=True):
                if name != Compression.NONE and unc[name]:
                    parts.append("%s [%d/%d chunks; %.2f%%]" % (name, count, n, 100.0 * comp[name] / unc[name]))
                else:
                    parts.append("%s [%d/%d chunks]" % (name, count, n))
            rows.append(("compression", ", ".join(parts)))
            if any(k != Compression.NONE for k in counts):
                total_unc, total_comp = sum(unc.values()), sum(comp.values())
                unc_s, comp_s = human_size(total_unc), human_size(total_comp)
                width = max(len(unc_s), len(comp_s))
                if duration > 0:
                    ur, cr = human_size(total_unc / duration), human_size(total_comp / duration)
                    rw = max(len(ur), len(cr))
                    rows.append(("uncompressed", "%*s @ %*s/s" % (width, unc_s, rw, ur)))
                    rows.append(("compressed", "%*s @ %*s/s (%.2f%%)" % (
                        width, comp_s, rw, cr, 100.0 * total_comp / max(total_unc, 1))))
                else:
                    rows.append(("uncompressed", "%*s" % (width, unc_s)))
                    rows.append(("compressed", "%*s" % (width, comp_s)))
        types = bag._datatypes()
        topics = bag._topic_table(with_freq=with_freq)
        if types and topics:
            tw = max(len(t) for t in types)
            topw = max(len(t) for t in topics)
            cw = max(len("%d" % t.message_count) for t in topics.values())
            freqs = {k: t.frequency for k, t in topics.items() if t.frequency is not None}
            fw = max((len(human_frequency(f)) for f in freqs.values()), default=0)
            for i, (name, (md5, _d)) in enumerate(types.items()):
                rows.append(("types" if i == 0 else "", "%-*s [%s]" % (tw, name, md5)))
            for i, (topic, t) in enumerate(topics.items()):
                s = "%-*s   %*d %s" % (topw, topic, cw, t.message_count, "msgs" if t.message_count > 1 else "msg ")
                if topic in freqs:
                    s += " @ %*s" % (fw, human_frequency(freqs[topic]))
                else:
                    s += "   %*s" % (fw, "")
                s += " : %-*s" % (tw, t.msg_type)
                if t.connections > 1:
                    s += " (%d connections)" % t.connections
                rows.append(("topics" if i == 0 else "", s))
    rows += _extra_rows(bag)
    width = max(len(f) for f, _ in rows) + 1
    out = ""
    for name, value in rows:
        out += "%-*s %s\n" % (width, name + ":" if name else "", value)
    return out.rstrip()


def _extra_rows(bag: Any) -> List[Tuple[str, str]]:
    """What a reader adds of its own (a rosbag2 recording's ROS 2 types and skipped topics)."""
    rows = getattr(getattr(bag, "_reader", None), "info_rows", None)
    return list(rows()) if rows is not None else []


def info_yaml(bag: Any, key: Optional[str] = None, with_freq: bool = False) -> Optional[str]:
    s = f"path: {bag.filename}\n" if bag.filename else ""
    s += f"version: {_version_str(bag)}\n"
    rng = bag._time_range()
    if rng is None:
        s += "size: %d\nindexed: False\n" % bag.size
    else:
        start, end = rng[0] / 1e9, rng[1] / 1e9
        s += "duration: %.6f\nstart: %.6f\nend: %.6f\n" % (end - start, start, end)
        s += "size: %d\nmessages: %d\nindexed: True\n" % (bag.size, bag.get_message_count())
        counts, unc, comp, _n = _compression_stats(bag)
        if not counts:
            s += "compression: none\n"
        else:
            main = sorted(((v, k) for k, v in counts.items()), reverse=True)[0][1]
            s += "compression: %s\n" % main
            if any(k != Compression.NONE for k in counts):
                s += "uncompressed: %d\ncompressed: %d\n" % (sum(unc.values()), sum(comp.values()))
        s += "types:\n"
        for name, (md5, _d) in bag._datatypes().items():
            s += "    - type: %s\n      md5: %s\n" % (name, md5)
        s += "topics:\n"
        for topic, t in bag._topic_table(with_freq=with_freq).items():
            s += "    - topic: %s\n      type: %s\n      messages: %d\n" % (topic, t.msg_type, t.message_count)
            if t.connections > 1:
                s += "      connections: %d\n" % t.connections
            if t.frequency is not None:
                s += "      frequency: %.4f\n" % t.frequency
        s += _extra_yaml(bag)
    if not key:
        return s
    return _yaml_key(s, key)


def _extra_yaml(bag: Any) -> str:
    reader = getattr(bag, "_reader", None)
    topics = getattr(reader, "topics", None)
    if reader is None or not hasattr(reader, "info_rows") or topics is None:
        return ""
    s = "ros2_types:\n"
    seen: Dict[str, str] = {}
    for t in topics.values():
        seen.setdefault(t.ros2_type, t.type_hash)
    for name, digest in sorted(seen.items()):
        s += "    - type: %s\n      type_hash: %s\n" % (name, digest or "''")
    if reader.skipped:
        s += "skipped:\n"
        for topic, (ros2_type, reason) in sorted(reader.skipped.items()):
            s += "    - topic: %s\n      type: %s\n      reason: %s\n" % (
                topic, ros2_type, json.dumps(reason))
    return s


class _Obj:
    def __init__(self, d: dict) -> None:
        for k, v in d.items():
            if isinstance(v, (list, tuple)):
                setattr(self, k, [_Obj(x) if isinstance(x, dict) else x for x in v])
            else:
                setattr(self, k, _Obj(v) if isinstance(v, dict) else v)


def _lookup(obj: Any, key: str) -> Any:
    """``obj.<key>`` for a dotted key with optional [index] parts (what rosbag's eval allows)."""
    import re

    for part in key.split("."):
        m = re.fullmatch(r"([A-Za-z_]\w*)((?:\[-?\d+\])*)", part)
        if not m:
            raise KeyError(key)
        obj = getattr(obj, m.group(1))
        for idx in re.findall(r"\[(-?\d+)\]", m.group(2)):
            obj = obj[int(idx)]
    return obj


def _yaml_key(s: str, key: str) -> Optional[str]:
    import yaml

    obj = _Obj(yaml.safe_load(s))
    try:
        val = _lookup(obj, key)
    except Exception:
        print(f'Error getting key "{key}"', file=sys.stderr)
        return None

    def show(val: Any, indent: int = 0) -> str:
        pad = "  " * indent
        if type(val) is list:
            return "".join("%s- %s\n" % (pad, show(item, indent + 1)) for item in val)
        if type(val) is _Obj:
            items = list(val.__dict__.items())
            out = ""
            for i, (k, v) in enumerate(items):
                if i:
                    out += pad
                out += "%s: %s" % (k, str(v))
                if i < len(items) - 1:
                    out += "\n"
            return out
        return pad + str(val)

    return show(val)
