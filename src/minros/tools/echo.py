"""Printing messages as ``rostopic echo`` does: genpy's YAML-like text, ``--noarr``/``--nostr``
placeholders, field selection (``/topic/field[1:3]/x``) and the ``-p`` CSV ("plot") form."""

from __future__ import annotations

import sys
from typing import Any, Callable, Dict, List, Tuple

from minros.msgs import Message, Time, TVal, strify_message

# ---------------------------------------------------------------------------------------------
# field selection

class FieldError(ValueError):
    """A field selection that cannot be parsed."""


def _index_or_slice(text: str) -> Any:
    if text == "":
        raise FieldError("empty array index")
    parts = text.split(":")
    if len(parts) == 1:
        try:
            return int(parts[0])
        except ValueError:
            raise FieldError(f"non-integer array index step '{parts[0]}'") from None
    if len(parts) > 3:
        raise FieldError("too many slice arguments")
    values: List[int | None] = [None, None, None]
    for i, (label, part) in enumerate(zip(("start", "stop", "step"), parts)):
        if part != "":
            try:
                values[i] = int(part)
            except ValueError:
                raise FieldError(f"non-integer slice {label} '{part}'") from None
    return slice(*values)


def parse_field_path(pattern: str) -> List[Tuple[str, Any]]:
    """``/pose/position[0:2]/x`` -> ``[('pose', None), ('position', slice(0, 2)), ('x', None)]``."""
    evals: List[Tuple[str, Any]] = []
    for part in (p for p in pattern.split("/") if p):
        if "[" in part:
            name, rest = part.split("[", 1)
            if not rest.endswith("]"):
                raise FieldError(f"missing closing ']' in slice spec '{part}'")
            try:
                evals.append((name, _index_or_slice(rest[:-1])))
            except FieldError as exc:
                raise FieldError(f"field '{name}' has invalid slice argument '{rest[:-1]}': {exc}") from None
        else:
            evals.append((part, None))
    return evals


def make_field_getter(pattern: str) -> Callable[[Any], Any] | None:
    """A function msg -> selected value (None and a note on stderr when absent)."""
    evals = parse_field_path(pattern)
    if not evals:
        return None

    def getter(msg: Any, steps: List[Tuple[str, Any]] = evals) -> Any:
        for i, (name, index) in enumerate(steps):
            try:
                msg = getattr(msg, name)
            except AttributeError:
                print(f"no field named {name} in {pattern}", file=sys.stderr)
                return None
            if index is not None:
                try:
                    msg = msg[index]
                except IndexError as exc:
                    print(f"{exc}: {pattern}", file=sys.stderr)
                    return None
                if isinstance(msg, (bytes, bytearray)) and isinstance(index, slice):
                    msg = list(msg)
                if isinstance(msg, list):
                    rest = steps[i + 1:]
                    if rest:
                        return [getter(m, rest) for m in msg]
                    return msg
        return msg

    return getter


def field_type(msg_class: Any, path: str) -> str | None:
    """Declared type of the field at ``path`` (``'pose/position/x'`` -> ``'float64'``)."""
    cls = msg_class
    type_name: str | None = None
    fields = [f for f in path.split("/") if f]
    for i, part in enumerate(fields):
        name = part.split("[")[0]
        slots = list(getattr(cls, "__slots__", []))
        if name not in slots:
            return None
        type_name = cls._slot_types[slots.index(name)]
        if i + 1 < len(fields):
            value = getattr(cls(), name)
            if isinstance(value, list):
                from minros.msgs.fill import _element_class, parse_type

                cls = _element_class(cls(), name, parse_type(type_name)[0])
                if cls is None:
                    return None
            else:
                cls = type(value)
    return type_name


# ---------------------------------------------------------------------------------------------
# --noarr / --nostr

_transformed_classes: Dict[Tuple[type, bool, bool], type] = {}


def _placeholder(value: Any, type_name: str, nostr: bool, noarr: bool) -> Any:
    if noarr and "[" in type_name:
        return f"<array type: {type_name.rstrip('[]').split('[')[0]}, length: {len(value)}>"
    if nostr and type_name == "string":
        return f"<string length: {len(value)}>"
    if nostr and type_name == "string[]":
        return f"<array type: string, length: {len(value)}>"
    return value


def make_value_transform(nostr: bool, noarr: bool) -> Callable[..., Any] | None:
    if not (nostr or noarr):
        return None

    def transform(val: Any, type_information: str | None = None) -> Any:
        if not isinstance(val, Message):
            if type_information is None:
                return val
            return _placeholder(val, type_information, nostr, noarr)
        cls = type(val)
        key = (cls, nostr, noarr)
        out_cls = _transformed_classes.get(key)
        if out_cls is None:
            types = []
            for type_name in cls._slot_types:
                replaced = (noarr and "[" in type_name) or (nostr and type_name in ("string", "string[]"))
                types.append("string" if replaced else type_name)
            out_cls = type("TransformedMessage", (Message,),
                           {"__slots__": tuple(cls.__slots__), "_slot_types": types,
                            "_type": cls._type, "_has_header": cls._has_header})
            _transformed_classes[key] = out_cls
        out = out_cls.__new__(out_cls)
        for name, type_name in zip(cls.__slots__, cls._slot_types):
            value = getattr(val, name)
            replaced = _placeholder(value, type_name, nostr, noarr)
            if replaced is value and isinstance(value, Message):
                replaced = transform(value)
            setattr(out, name, replaced)
        return out

    return transform


def make_field_filter(nostr: bool, noarr: bool) -> Callable[[Any], Any]:
    def field_filter(val: Any) -> Any:
        for name, type_name in zip(val.__slots__, val._slot_types):
            if noarr and "[" in type_name:
                continue
            if nostr and "string" in type_name:
                continue
            yield name

    return field_filter


# ---------------------------------------------------------------------------------------------
# -p (CSV)

def _convert_getattr(val: Any, name: str, type_name: str) -> Any:
    value = getattr(val, name)
    if "uint8[" in type_name and isinstance(value, (bytes, bytearray, str)):
        return list(value) if not isinstance(value, str) else [ord(c) for c in value]
    return value


def _is_message(val: Any) -> bool:
    return hasattr(val, "_slot_types")


def plot_fields(val: Any, prefix: str, field_filter: Callable | None) -> str | None:
    if type(val) in (bool, int, float) or isinstance(val, TVal) or isinstance(val, str):
        return prefix
    if _is_message(val):
        fields = list(field_filter(val)) if field_filter is not None else val.__slots__
        sub = [plot_fields(_convert_getattr(val, f, t), f"{prefix}.{f}", field_filter)
               for f, t in zip(val.__slots__, val._slot_types) if f in fields]
        sub = [s for s in sub if s is not None]
        return ",".join(sub) if sub else None
    if isinstance(val, (list, tuple)):
        if not val:
            return None
        first = val[0]
        if type(first) in (bool, int, float) or isinstance(first, (TVal, str)):
            return ",".join(f"{prefix}{i}" for i in range(len(val)))
        if _is_message(first):
            sub = [plot_fields(v, f"{prefix}{i}", field_filter) for i, v in enumerate(val)]
            sub = [s for s in sub if s]
            return ",".join(sub) if sub else None
    return None


def plot_header(val: Any, field_filter: Callable | None) -> str:
    text = plot_fields(val, "field", field_filter)
    return "%time," + text if text is not None else "%time,"


def _plot_values(val: Any, time_offset: Time | None, field_filter: Callable | None) -> str | None:
    if type(val) is bool:
        return "1" if val else "0"
    if type(val) in (int, float) or isinstance(val, TVal):
        if time_offset is not None and isinstance(val, Time):
            return str(val - time_offset)
        return str(val)
    if _is_message(val):
        fields = list(field_filter(val)) if field_filter is not None else val.__slots__
        sub = [_plot_values(_convert_getattr(val, f, t), time_offset, field_filter)
               for f, t in zip(val.__slots__, val._slot_types) if f in fields]
        sub = [s for s in sub if s is not None]
        return ",".join(sub) if sub else None
    if isinstance(val, str):
        return val
    if isinstance(val, (list, tuple)):
        if not val:
            return None
        first = val[0]
        if type(first) is bool:
            return ",".join("1" if v else "0" for v in val)
        if type(first) in (int, float) or isinstance(first, TVal):
            return ",".join(str(v) for v in val)
        if isinstance(first, str):
            return ",".join(val)
        if _is_message(first):
            sub = [s for s in (_plot_values(v, time_offset, field_filter) for v in val) if s is not None]
            return ",".join(sub) if sub else None
    return None


def plot_line(val: Any, now: Time, time_offset: Time | None = None,
              field_filter: Callable | None = None, header_first: bool = True) -> str:
    """The ``-p`` CSV line: the header's stamp (unless not ``header_first``) or ``now`` in ns,
    less ``time_offset``, then the values."""
    text = _plot_values(val, time_offset, field_filter) or ""
    offset = time_offset.to_nsec() if time_offset is not None else 0
    if header_first and getattr(val, "_has_header", False):
        return f"{val.header.stamp.to_nsec() - offset},{text}"
    return f"{now.to_nsec() - offset},{text}"


# ---------------------------------------------------------------------------------------------
# YAML

def yaml_text(val: Any, type_information: str | None = None, time_offset: Time | None = None,
              value_transform: Callable | None = None, fixed_numeric_width: int | None = None) -> str:
    if type_information and type_information.startswith("uint8[") and isinstance(val, (bytes, bytearray)):
        val = list(val)
    if value_transform is not None:
        val = value_transform(val, type_information)
    return strify_message(val, time_offset=time_offset, fixed_numeric_width=fixed_numeric_width)
