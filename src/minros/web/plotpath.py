"""Plot field paths with rqt_plot's syntax, for the page's plot view (pure: no ROS, no sockets).

What a user types, as ``rqt_plot`` reads its arguments and its topic box:

* one or more expressions separated by spaces or commas: ``/turtle1/pose/x /turtle2/pose/x``;
* ``/topic/field1:field2:field3`` is short for three paths that share ``/topic/``:
  ``/turtle1/pose/x:y`` plots ``/turtle1/pose/x`` and ``/turtle1/pose/y``;
* a path is the topic (the longest topic the master knows that prefixes it), then fields
  separated by ``/``, with ``[i]`` to index an array: ``/imu/orientation_covariance[4]``,
  ``/tf/transforms[0]/transform/translation/x``;
* a path that ends on a message plots its numeric (non-array) fields (``/turtle1/pose`` plots
  x, y, theta, linear_velocity and angular_velocity); one that ends on a fixed-size numeric
  array plots each element; a variable-size array needs an index, as in rqt_plot.

The x value of a point is the message's ``header.stamp`` when its type has a header, else the
time it was received (rqt_plot's rule). The error texts are rqt_plot's where it has one.
``bool`` fields plot as 0 and 1, ``time``/``duration`` fields as seconds.
"""

from __future__ import annotations

import re
from dataclasses import dataclass
from typing import Any, Callable, Dict, List, Optional, Sequence, Tuple

NUMERIC = frozenset(("byte", "char", "int8", "uint8", "int16", "uint16", "int32", "uint32",
                     "int64", "uint64", "float32", "float64", "bool", "time", "duration"))
_STEP = re.compile(r"^([A-Za-z][A-Za-z0-9_]*)(?:\[(\d+)\])?$")
_SLOT = re.compile(r"^(.*?)(?:\[(\d*)\])?$")

#: one step of a path: a field name, and an index into it when the field is an array
Step = Tuple[str, Optional[int]]


class PlotPathError(ValueError):
    """An expression that cannot be plotted; the text says why (and how to fix it)."""


def split_expressions(text: str) -> List[str]:
    """The field paths of what a user typed (spaces/commas between paths, ``a/x:y`` shorthand)."""
    paths: List[str] = []
    for part in re.split(r"[\s,]+", text.strip()):
        if not part:
            continue
        if ":" in part:
            head, *more = part.split(":")
            if "/" not in head:
                raise PlotPathError(f"{part} must contain a topic and field name")
            paths.append(head)
            base = head[:head.rfind("/")]
            paths.extend(f"{base}/{field}" for field in more if field)
        else:
            paths.append(part)
    if not paths:
        raise PlotPathError("type a field path, e.g. /turtle1/pose/x (several: /turtle1/pose/x:y)")
    return [p if p.startswith("/") else "/" + p for p in paths]


def find_topic(path: str, topic_types: Dict[str, str]) -> Tuple[str, str, str]:
    """``(topic, type, rest)``: the longest known topic that ``path`` starts with."""
    matches = [t for t in topic_types if path == t or path.startswith(t.rstrip("/") + "/")]
    if not matches:
        raise PlotPathError(f"topic {path} does not exist")
    topic = max(matches, key=len)
    type_name = topic_types[topic]
    if not type_name or type_name == "*":
        raise PlotPathError(f"type of topic {path} is unknown")
    return topic, type_name, path[len(topic):]


def parse_steps(rest: str, topic: str) -> List[Step]:
    steps: List[Step] = []
    for part in (p for p in rest.split("/") if p):
        match = _STEP.match(part)
        if match is None:
            raise PlotPathError(f"invalid field {part} in topic {topic}")
        steps.append((match.group(1), int(match.group(2)) if match.group(2) is not None else None))
    return steps


def _slot(slot_type: str) -> Tuple[str, bool, Optional[int]]:
    """``'float64[9]'`` -> ``('float64', True, 9)``."""
    match = _SLOT.match(slot_type)
    assert match is not None
    base, size = match.group(1), match.group(2)
    if size is None:
        return base, False, None
    return base, True, int(size) if size else None


@dataclass(frozen=True)
class PlotField:
    """One plotted series: its full name and how to read its value from a message."""

    name: str
    topic: str
    steps: Tuple[Step, ...]

    def value(self, msg: Any) -> Optional[float]:
        """The field of ``msg`` as a float; None when an index is out of range this time."""
        val = msg
        try:
            for field, index in self.steps:
                val = getattr(val, field)
                if index is not None:
                    val = val[index]
        except IndexError:
            return None
        return as_number(val)


def as_number(val: Any) -> float:
    if hasattr(val, "to_sec"):
        return float(val.to_sec())
    return float(val)


def plot_fields(path: str, topic_types: Dict[str, str],
                get_class: Callable[[str], type]) -> Tuple[List[PlotField], str]:
    """The series ``path`` stands for and rqt_plot's description of them; PlotPathError when
    nothing there can be plotted."""
    topic, type_name, rest = find_topic(path, topic_types)
    try:
        cls: Any = get_class(type_name)
    except Exception:
        raise PlotPathError(f"type of topic {path} is unknown ({type_name} is not installed "
                            "here)") from None
    steps = parse_steps(rest, topic)
    base, is_array, size = type_name, False, None
    walked = ""
    for field, index in steps:
        if is_array:
            raise PlotPathError(f"{topic}{walked} is an array: index it, e.g. {topic}{walked}[0]")
        slots = list(getattr(cls, "__slots__", ()))
        if field not in slots or not hasattr(cls, "_slot_types"):
            raise PlotPathError(f"no field {rest.lstrip('/')} in topic {topic}")
        base, is_array, size = _slot(cls._slot_types[slots.index(field)])
        walked += f"/{field}"
        if index is not None:
            if not is_array:
                raise PlotPathError(f"{topic}{walked} is not an array: remove [{index}]")
            if size is not None and index >= size:
                raise PlotPathError(f"{topic}{walked} has {size} elements: [{index}] is out of "
                                    "range")
            is_array = False
            walked += f"[{index}]"
        if base not in NUMERIC and base != "string":
            cls = get_class(base)
    name = topic + walked
    if base in NUMERIC:
        kind = "boolean" if base == "bool" else "numeric"
        if not is_array:
            return [PlotField(name, topic, tuple(steps))], f"topic {name} is {kind}"
        if size is None:
            raise PlotPathError(f"topic {name} is variable-size {kind} array: index it, e.g. "
                                f"{name}[0]")
        last, _ = steps[-1]
        fields = [PlotField(f"{name}[{i}]", topic, (*steps[:-1], (last, i))) for i in range(size)]
        return fields, f"topic {name} is fixed-size {kind} array"
    if base == "string":
        raise PlotPathError(f"Topic {name} is not numeric")
    if is_array:
        raise PlotPathError(f"{name} is an array of {base}: index it, e.g. {name}[0]")
    fields = []
    for slot, slot_type in zip(cls.__slots__, cls._slot_types):
        slot_base, slot_array, _ = _slot(slot_type)
        if slot_base in NUMERIC and slot_base != "bool" and not slot_array:
            fields.append(PlotField(f"{name}/{slot}", topic, (*steps, (slot, None))))
    if not fields:
        raise PlotPathError(f"No plottable fields in {name}")
    return fields, f"{len(fields)} plottable fields in {name}"


def resolve(text: str, topic_types: Dict[str, str],
            get_class: Callable[[str], type]) -> List[PlotField]:
    """Every series of what a user typed, in order, without repeats; the first error raised."""
    out: List[PlotField] = []
    for path in split_expressions(text):
        for found in plot_fields(path, topic_types, get_class)[0]:
            if found not in out:
                out.append(found)
    return out


def stamp_of(msg: Any, receive_sec: float) -> float:
    """The x value of a message: its header stamp when its type has one, else receive time."""
    if getattr(type(msg), "_has_header", False):
        stamp = msg.header.stamp
        return stamp.secs + stamp.nsecs * 1e-9
    return receive_sec


def group_by_topic(fields: Sequence[PlotField]) -> Dict[str, List[Tuple[int, PlotField]]]:
    """``{topic: [(series index, field), ...]}``: one subscription per topic."""
    groups: Dict[str, List[Tuple[int, PlotField]]] = {}
    for index, field in enumerate(fields):
        groups.setdefault(field.topic, []).append((index, field))
    return groups

