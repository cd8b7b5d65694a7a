"""Generate readable Python source for a message class from its spec.

One class per message type, compiled once. Nested message fields are expanded in place (as
genpy does), so consecutive fixed-size fields - across nesting levels, including the length
prefix of the string or array that follows them - are packed and unpacked by one precompiled
``struct.Struct``. Deserialization works on a ``memoryview`` with offsets (no intermediate
copies) and checks every length and count against the bytes that remain before using it.
"""

from __future__ import annotations

import keyword
import re
import struct
from typing import Callable, Dict, List, Tuple

from .runtime import EXPORTS
from .spec import MsgSpec

#: struct codes for writing each primitive
SER_CODE = {
    "int8": "b", "byte": "b", "uint8": "B", "char": "B", "int16": "h", "uint16": "H",
    "int32": "i", "uint32": "I", "int64": "q", "uint64": "Q", "float32": "f", "float64": "d",
    "bool": "B",
}
#: struct codes for reading: bool reads with '?' so any non-zero byte becomes True (genpy: bool())
DESER_CODE = dict(SER_CODE, bool="?")
_SIZE = {c: struct.calcsize("<" + c) for c in "bBhHiIqQfd?"}
_DEFAULTS = {"float32": "0.0", "float64": "0.0", "string": "''", "bool": "False",
             "time": "_Time()", "duration": "_Duration()"}

GetSpec = Callable[[str], MsgSpec]


def python_name(field_name: str) -> str:
    """The attribute name of a field (genpy appends '_' to Python keywords)."""
    return field_name + "_" if keyword.iskeyword(field_name) else field_name


def dep_name(type_name: str) -> str:
    """The module-level name bound to the class of embedded type ``pkg/Type``."""
    return "_" + type_name.replace("/", "_")


def numpy_class_name(type_name: str) -> str:
    """rospy's name for the numpy_msg class of ``type_name``: ``Numpy_pkg__Type``."""
    return "Numpy_" + type_name.replace("/", "__")


def in_place_class_name(type_name: str) -> str:
    """The name of the in-place variant of ``type_name`` (see ``generate_source``)."""
    return "InPlace_" + type_name.replace("/", "__")


def _compress(run: List[Tuple[int, str]]) -> str:
    merged: List[List] = []
    for count, code in run:
        if merged and merged[-1][1] == code:
            merged[-1][0] += count
        else:
            merged.append([count, code])
    return "".join((str(n) if n != 1 else "") + c for n, c in merged)


def _struct_name(fmt: str) -> str:
    return "_S_" + fmt.replace("?", "Bool")


def min_size(spec: MsgSpec, get_spec: GetSpec) -> int:
    """The fewest bytes any instance of ``spec`` takes on the wire."""
    total = 0
    for f in spec.fields:
        if f.base_type in SER_CODE:
            one = _SIZE[SER_CODE[f.base_type]]
        elif f.base_type in ("time", "duration"):
            one = 8
        elif f.base_type == "string":
            one = 4
        else:
            one = min_size(get_spec(f.base_type), get_spec)
        if f.is_array:
            total += 4 if f.array_len is None else one * f.array_len
        else:
            total += one
    return total


BUILTIN_NAMES = frozenset(SER_CODE) | {"string", "time", "duration"}


def _flat_codes(spec: MsgSpec, get_spec: GetSpec) -> List[Tuple[int, str]]:
    out: List[Tuple[int, str]] = []
    for f in spec.fields:
        if f.base_type in DESER_CODE:
            out.append((1, DESER_CODE[f.base_type]))
        else:
            out.extend(_flat_codes(get_spec(f.base_type), get_spec))
    return out


def is_flat(spec: MsgSpec, get_spec: GetSpec) -> bool:
    """Whether ``spec`` is a non-empty run of fixed-size primitives (nested ones included):
    arrays of such messages are packed and unpacked element by element in one pass."""
    if not spec.fields:
        return False
    for f in spec.fields:
        if f.is_array:
            return False
        if f.base_type in SER_CODE:
            continue
        if f.is_builtin or not is_flat(get_spec(f.base_type), get_spec):
            return False
    return True


def has_bulk_arrays(spec: MsgSpec, get_spec: GetSpec) -> bool:
    """Whether ``spec`` (or an embedded type) has a variable-length primitive array.

    Only such messages can be large enough for copying the received bytes to matter, so only
    they are deserialized from a ``memoryview``; the others from ``bytes`` (faster to decode).
    """
    for f in spec.fields:
        if f.is_array and f.array_len is None and (f.base_type in SER_CODE or f.base_type == "char"):
            return True
        if not f.is_builtin and has_bulk_arrays(get_spec(f.base_type), get_spec):
            return True
    return False


class _Writer:
    """Collects indented source lines and the Structs they use."""

    def __init__(self, structs: Dict[str, str]) -> None:
        self.lines: List[str] = []
        self.structs = structs
        self.counter = 0

    def emit(self, indent: int, line: str) -> None:
        self.lines.append("    " * indent + line)

    def tmp(self, prefix: str) -> str:
        self.counter += 1
        return f"{prefix}{self.counter}"

    def struct(self, fmt: str) -> str:
        name = _struct_name(fmt)
        self.structs[fmt] = name
        return name


class _SerializerGen(_Writer):
    def __init__(self, structs: Dict[str, str], get_spec: GetSpec) -> None:
        super().__init__(structs)
        self.get_spec = get_spec
        self.out = "append"  # the function that receives each piece
        self.run: List[Tuple[int, str, str]] = []  # (count, code, expression)

    def flush(self, ind: int) -> None:
        if not self.run:
            return
        fmt = _compress([(n, c) for n, c, _ in self.run])
        name = self.struct(fmt)
        self.emit(ind, f"{self.out}({name}.pack({', '.join(e for _, _, e in self.run)}))")
        self.run = []

    def string(self, ind: int, expr: str) -> None:
        var = self.tmp("_s")
        self.emit(ind, f"{var} = {expr}")
        self.emit(ind, f"if {var}.__class__ is str:")
        self.emit(ind + 1, f"{var} = {var}.encode()")
        self.emit(ind, f"elif {var}.__class__ is not bytes:")
        self.emit(ind + 1, f"{var} = _string_bytes({var})")
        self.run.append((1, "I", f"len({var})"))
        self.flush(ind)
        self.emit(ind, f"{self.out}({var})")

    def tval(self, expr: str, bt: str) -> None:
        """A time (unsigned secs) or duration (signed secs) as two 32-bit fields."""
        code = "I" if bt == "time" else "i"
        self.run.append((1, code, f"{expr}.secs"))
        self.run.append((1, code, f"{expr}.nsecs"))

    def sized(self, ind: int, var: str, n: int | None, fpath: str) -> None:
        """The length prefix of a variable array, or the length check of a fixed one; then
        the pending run is written, so the elements can follow."""
        if n is None:
            self.run.append((1, "I", f"len({var})"))
        else:
            self.emit(ind, f"if len({var}) != {n}:")
            self.emit(ind + 1, f"raise _bad_length({fpath!r}, {n}, len({var}))")
        self.flush(ind)

    def fields(self, spec: MsgSpec, obj: str, path: str, ind: int) -> None:
        for f in spec.fields:
            attr = python_name(f.name)
            expr = f"{obj}.{attr}"
            fpath = path + attr
            bt = f.base_type
            if not f.is_array:
                if bt in SER_CODE:
                    self.run.append((1, SER_CODE[bt], expr))
                elif bt in ("time", "duration"):
                    var = self.tmp("_t")
                    self.emit(ind, f"{var} = {expr}")
                    self.tval(var, bt)
                elif bt == "string":
                    self.string(ind, expr)
                else:
                    var = self.tmp("_m")
                    self.emit(ind, f"{var} = {expr}")
                    self.fields(self.get_spec(bt), var, fpath + ".", ind)
                continue
            n = f.array_len
            if bt in ("uint8", "char"):
                var = self.tmp("_b")
                self.emit(ind, f"{var} = {expr}")
                self.emit(ind, f"if {var}.__class__ is not bytes:")
                self.emit(ind + 1, f"{var} = _as_bytes({var})")
                self.sized(ind, var, n, fpath)
                self.emit(ind, f"{self.out}({var})")
            elif bt in SER_CODE:
                code = SER_CODE[bt]
                if n is None:
                    self.flush(ind)
                    self.emit(ind, f"_put_array({self.out}, {code!r}, {expr})")
                elif n > 0:
                    var = self.tmp("_a")
                    self.emit(ind, f"{var} = {expr}")
                    self.emit(ind, f"if {var}.__class__ is not list and {var}.__class__ is not tuple:")
                    self.emit(ind + 1, f"{var} = _as_list({var}, {n}, {fpath!r})")
                    self.emit(ind, f"if len({var}) != {n}:")
                    self.emit(ind + 1, f"raise _bad_length({fpath!r}, {n}, len({var}))")
                    self.run.append((n, code, f"*{var}"))
            else:
                var = self.tmp("_a")
                self.emit(ind, f"{var} = {expr}")
                self.sized(ind, var, n, fpath)
                item = self.tmp("_e")
                if bt not in BUILTIN_NAMES and is_flat(self.get_spec(bt), self.get_spec):
                    # small fixed-size elements: pack them all, hand over one piece
                    parts, outer = self.tmp("_p"), self.out
                    self.emit(ind, f"{parts} = []")
                    self.out = f"{parts}.append"
                    self.emit(ind, f"for {item} in {var}:")
                    self.fields(self.get_spec(bt), item, fpath + "[].", ind + 1)
                    self.flush(ind + 1)
                    self.out = outer
                    self.emit(ind, f"{self.out}(b''.join({parts}))")
                    continue
                self.emit(ind, f"for {item} in {var}:")
                if bt == "string":
                    self.string(ind + 1, item)
                elif bt in ("time", "duration"):
                    self.tval(item, bt)
                else:
                    self.fields(self.get_spec(bt), item, fpath + "[].", ind + 1)
                self.flush(ind + 1)
                if len(self.lines) and self.lines[-1].endswith(":"):
                    self.emit(ind + 1, "pass")


class _DeserializerGen(_Writer):
    def __init__(self, structs: Dict[str, str], get_spec: GetSpec, type_name: str,
                 numpy: bool, in_place: bool = False) -> None:
        super().__init__(structs)
        self.in_place = in_place
        self.get_spec = get_spec
        self.type_name = type_name
        self.numpy = numpy
        self.views = has_bulk_arrays(get_spec(type_name), get_spec)
        self.run: List[Tuple[int, str, str]] = []  # (count, code, target)
        self.post: List[str] = []

    def flush(self, ind: int) -> None:
        if not self.run:
            return
        run = [(n, c) for n, c, _ in self.run]
        fmt = _compress(run)
        size = struct.calcsize("<" + fmt)
        name = self.struct(fmt)
        targets = ", ".join(t for _, _, t in self.run)
        if len(self.run) == 1:
            targets += ","
        self.emit(ind, f"{targets} = {name}.unpack_from(view, end)")
        self.emit(ind, f"end += {size}")
        for line in self.post:
            self.emit(ind, line)
        self.run = []
        self.post = []

    def tval(self, ind: int, var: str, bt: str) -> None:
        code = "I" if bt == "time" else "i"
        self.run.append((1, code, f"{var}.secs"))
        self.run.append((1, code, f"{var}.nsecs"))
        if bt == "time":
            self.post.append(f"if {var}.nsecs >= 1000000000:")
        else:
            self.post.append(f"if not 0 <= {var}.nsecs < 1000000000:")
        self.post.append(f"    {var}.canon()")

    def length(self, ind: int) -> str:
        """Read a uint32 length/count as part of the current run; returns its variable."""
        var = self.tmp("_n")
        self.run.append((1, "I", var))
        self.flush(ind)
        return var

    def need(self, ind: int, nbytes: str | int, fpath: str) -> None:
        """Check that ``nbytes`` bytes remain before reading them (a clear error, no overrun)."""
        self.emit(ind, f"if {nbytes} > len(view) - end:")
        self.emit(ind + 1, f"raise _overrun({self.type_name!r}, {fpath!r}, {nbytes}, len(view) - end)")

    def string_body(self, ind: int, target: str, length: str, fpath: str) -> None:
        self.need(ind, length, fpath)
        if self.views:
            # the data may be a memoryview (large messages are not copied): str() decodes both
            # not UTF-8: U+FFFD, and one ERROR per message type, as genpy's 'rosmsg' handler
            self.emit(ind, f"{target} = str(view[end:end + {length}], 'utf-8', _TEXT_ERRORS)")
        else:
            self.emit(ind, f"{target} = view[end:end + {length}].decode('utf-8', _TEXT_ERRORS)")
        self.emit(ind, f"end += {length}")

    def fields(self, spec: MsgSpec, obj: str, path: str, ind: int, reuse: bool = False) -> None:
        """Read the fields of ``spec`` into ``obj``.

        With ``reuse`` (the message being filled was built by its constructor), embedded
        messages and times already present are filled in place, as genpy does, instead of
        being replaced by new objects; elements of arrays are always new objects.
        """
        for f in spec.fields:
            attr = python_name(f.name)
            target = f"{obj}.{attr}"
            fpath = path + attr
            bt = f.base_type
            if not f.is_array:
                if bt in DESER_CODE:
                    self.run.append((1, DESER_CODE[bt], target))
                elif bt in ("time", "duration"):
                    var = self.tmp("_t")
                    cls = "_Time" if bt == "time" else "_Duration"
                    if reuse:
                        self.emit(ind, f"{var} = {target}")
                        self.emit(ind, f"if {var}.__class__ is not {cls}:")
                        self.emit(ind + 1, f"{var} = {target} = _new({cls})")
                    else:
                        self.emit(ind, f"{var} = {target} = _new({cls})")
                    self.tval(ind, var, bt)
                elif bt == "string":
                    length = self.length(ind)
                    self.string_body(ind, target, length, fpath)
                else:
                    var = self.tmp("_m")
                    cls = dep_name(bt)
                    if reuse:
                        self.emit(ind, f"{var} = {target}")
                        self.emit(ind, f"if {var}.__class__ is not {cls}:")
                        self.emit(ind + 1, f"{var} = {target} = {cls}()")
                    else:
                        self.emit(ind, f"{var} = {target} = _new({cls})")
                    self.fields(self.get_spec(bt), var, fpath + ".", ind, reuse)
                continue
            n = f.array_len
            if bt in ("uint8", "char"):
                if n is None:
                    count = self.length(ind)
                    self.need(ind, count, fpath)
                    if self.numpy:
                        self.emit(ind, f"{target} = _numpy_view('B', {count}, view, end)")
                    elif self.in_place:  # a slice of the data: a view when it is a memoryview
                        self.emit(ind, f"{target} = view[end:end + {count}]")
                    else:
                        self.emit(ind, f"{target} = bytes(view[end:end + {count}])")
                    self.emit(ind, f"end += {count}")
                else:
                    self.flush(ind)
                    if self.numpy:
                        self.need(ind, n, fpath)
                        self.emit(ind, f"{target} = _numpy_view('B', {n}, view, end)")
                    else:
                        name = self.struct(f"{n}s")
                        self.emit(ind, f"{target}, = {name}.unpack_from(view, end)")
                    self.emit(ind, f"end += {n}")
            elif bt in DESER_CODE:
                code = DESER_CODE[bt]
                size = _SIZE[code]
                if n is None:
                    count = self.length(ind)
                    nbytes = self.tmp("_k")
                    self.emit(ind, f"{nbytes} = {count} * {size}" if size != 1 else f"{nbytes} = {count}")
                    self.emit(ind, f"if {nbytes} > len(view) - end:")
                    self.emit(ind + 1, f"raise _too_many({self.type_name!r}, {fpath!r}, {count}, len(view) - end)")
                    self._numeric_array(ind, target, code, count, bt)
                    self.emit(ind, f"end += {nbytes}")
                else:
                    self.flush(ind)
                    if self.numpy and bt != "bool":
                        self.need(ind, n * size, fpath)
                        self.emit(ind, f"{target} = _numpy_view({code!r}, {n}, view, end)")
                    else:
                        name = self.struct(f"{n}{code}")
                        if bt == "bool":
                            self.emit(ind, f"{target} = list({name}.unpack_from(view, end))")
                        else:
                            self.emit(ind, f"{target} = {name}.unpack_from(view, end)")
                    self.emit(ind, f"end += {n * size}")
            else:
                if n is None:
                    count = self.length(ind)
                    if bt == "string":
                        least = 4
                    elif bt in ("time", "duration"):
                        least = 8
                    else:
                        least = min_size(self.get_spec(bt), self.get_spec)
                    if least:
                        self.emit(ind, f"if {count} * {least} > len(view) - end:")
                    else:
                        self.emit(ind, f"if {count} > _MAX_EMPTY_ELEMENTS:")
                    self.emit(ind + 1, f"raise _too_many({self.type_name!r}, {fpath!r}, {count}, len(view) - end)")
                else:
                    self.flush(ind)
                    count = str(n)
                items = self.tmp("_l")
                self.emit(ind, f"{items} = {target} = []")
                if bt not in BUILTIN_NAMES and is_flat(self.get_spec(bt), self.get_spec):
                    self._flat_array(ind, items, bt, count, fpath)
                    continue
                self.emit(ind, f"for _ in range({count}):")
                if bt == "string":
                    length = self.length(ind + 1)
                    var = self.tmp("_v")
                    self.string_body(ind + 1, var, length, fpath + "[]")
                    self.emit(ind + 1, f"{items}.append({var})")
                elif bt in ("time", "duration"):
                    var = self.tmp("_t")
                    cls = "_Time" if bt == "time" else "_Duration"
                    self.emit(ind + 1, f"{var} = _new({cls})")
                    self.emit(ind + 1, f"{items}.append({var})")
                    self.tval(ind + 1, var, bt)
                else:
                    var = self.tmp("_e")
                    self.emit(ind + 1, f"{var} = _new({dep_name(bt)})")
                    self.emit(ind + 1, f"{items}.append({var})")
                    self.fields(self.get_spec(bt), var, fpath + "[].", ind + 1)
                self.flush(ind + 1)

    def _flat_array(self, ind: int, items: str, bt: str, count: str, fpath: str) -> None:
        """Elements of fixed-size primitives only: one ``iter_unpack`` over the whole array."""
        sub = _DeserializerGen(self.structs, self.get_spec, self.type_name, self.numpy,
                               self.in_place)
        sub.counter = self.counter
        var = sub.tmp("_e")
        sub.emit(0, f"{var} = _new({dep_name(bt)})")
        sub.fields(self.get_spec(bt), var, fpath + "[].", 0)
        sub.flush(0)
        self.counter = sub.counter
        unpack = [line for line in sub.lines if ".unpack_from(view, end)" in line]
        size = struct.calcsize("<" + _compress(
            [(n, c) for n, c in _flat_codes(self.get_spec(bt), self.get_spec)]))
        targets, _, call = unpack[0].partition(" = ")
        struct_name = call.split(".", 1)[0]
        values = self.tmp("_v")
        if count.isdigit():  # fixed length: variable ones were checked against the data already
            self.need(ind, f"{count} * {size}", fpath)
        self.emit(ind, f"for {values} in {struct_name}.iter_unpack(view[end:end + {count} * {size}]):")
        for line in sub.lines:
            if line in unpack or line.startswith("end += "):
                continue
            self.emit(ind + 1, line)
        self.emit(ind + 1, f"{targets} = {values}")
        self.emit(ind + 1, f"{items}.append({var})")
        self.emit(ind, f"end += {count} * {size}")

    def _numeric_array(self, ind: int, target: str, code: str, count: str, bt: str) -> None:
        if bt == "bool":
            self.emit(ind, f"{target} = list(_unpack_array('?', {count}, view, end))")
        elif self.numpy:
            self.emit(ind, f"{target} = _numpy_view({code!r}, {count}, view, end)")
        else:
            self.emit(ind, f"{target} = _unpack_array({code!r}, {count}, view, end)")


def default_value(type_: str, base_type: str, is_array: bool, array_len: int | None) -> str:
    """Python expression for a field's default value (genpy's defaults)."""
    if not is_array:
        if base_type in _DEFAULTS:
            return _DEFAULTS[base_type]
        if base_type in SER_CODE:
            return "0"
        return f"{dep_name(base_type)}()"
    if base_type in ("uint8", "char"):
        return "b''" if array_len is None else f"b'\\x00' * {array_len}"
    if array_len is None:
        return "[]"
    item = default_value(base_type, base_type, False, None)
    if base_type in SER_CODE or base_type == "string":
        return f"[{item}] * {array_len}"
    return f"[{item} for _ in range({array_len})]"


def generate_source(spec: MsgSpec, get_spec: GetSpec, md5sum: str, full_text: str,
                    module: str | None = None, numpy: bool = False,
                    in_place: bool = False) -> str:
    """Python source defining the class for ``spec`` (named as its short name).

    The module needs ``_load(type_name) -> class`` in its globals for embedded types; with
    ``numpy=True`` it also needs ``_base_class`` and defines a subclass whose numeric arrays
    deserialize as numpy views; with ``in_place=True`` one whose variable-length ``uint8[]`` and
    ``char[]`` fields are slices of the data read (memoryviews of it, not copies), which the
    shared-memory transport reads its slots with.
    """
    name = spec.short_name
    structs: Dict[str, str] = {}
    deps: List[str] = []
    for f in spec.fields:
        if not f.is_builtin:
            _collect_deps(f.base_type, get_spec, deps)
    attrs = [python_name(f.name) for f in spec.fields]

    ser = _SerializerGen(structs, get_spec)
    ser.fields(spec, "self", "", 2)
    ser.flush(2)
    de = _DeserializerGen(structs, get_spec, spec.full_name, numpy, in_place)
    de.fields(spec, "self", "", 2, reuse=True)
    de.flush(2)
    # for a message made by __new__ (no fields yet): embedded messages and times are new
    # objects, so receivers skip building default fields that the data replaces anyway
    fresh = _DeserializerGen(structs, get_spec, spec.full_name, numpy, in_place)
    fresh.fields(spec, "self", "", 2, reuse=False)
    fresh.flush(2)

    out: List[str] = []
    if deps:
        out.append("")
        out.append("# classes of the embedded message types")
        for d in deps:
            out.append(f"{dep_name(d)} = _load({d!r})")
    if structs:
        out.append("")
        out.append("# fixed-size runs of fields, packed/unpacked in one call")
        for fmt, sname in sorted(structs.items(), key=lambda kv: kv[1]):
            out.append(f"{sname} = _Struct({'<' + fmt!r})")
    if any("_TEXT_ERRORS" in line for gen in (de, fresh) for line in gen.lines):
        out.append("")
        out.append("# how its strings decode: bytes that are not UTF-8 become U+FFFD, logged once")
        out.append(f"_TEXT_ERRORS = _decoding_errors({spec.full_name!r})")
    out.append("")
    out.append("")
    if in_place:
        out.append(f"class {in_place_class_name(spec.full_name)}(_base_class):")
        out.append(f'    """{spec.full_name} whose byte arrays are views of the received bytes."""')
        out.append("")
        out.append(f"    __slots__ = {attrs!r}")
        out.append("    _keeps_buffer = True  # its byte arrays are views of the received bytes")
    elif numpy:
        out.append(f"class {numpy_class_name(spec.full_name)}(_base_class):")
        out.append(f'    """{spec.full_name} whose numeric arrays are numpy views of the received bytes."""')
        out.append("")
        out.append(f"    __slots__ = {attrs!r}  # as rospy's numpy_msg: same fields, re-declared")
        out.append("    _keeps_buffer = True  # its arrays are views of the received bytes")
    else:
        out.append(f"class {name}(_Message):")
        out.append(f'    """{spec.full_name} (md5sum {md5sum})."""')
        out.append("")
        out.append(f"    __slots__ = {attrs!r}")
        out.append(f"    _type = {spec.full_name!r}")
        out.append(f"    _md5sum = {md5sum!r}")
        out.append(f"    _has_header = {spec.has_header!r}")
        out.append(f"    _zero_copy = {de.views!r}  # True: deserialize() reads big input in place (memoryview)")
        out.append("    _keeps_buffer = False  # every field is copied out of the received bytes")
        out.append(f"    _full_text = {_text_literal(full_text, 8)}")
        out.append(f"    _slot_types = {spec.types!r}")
        if module:
            out.append(f"    __module__ = {module!r}")
        if spec.constants:
            out.append("")
            for c in spec.constants:
                out.append(f"    {c.name} = {c.value!r}")
        out.append("")
        out.append("    def __init__(self, *args, **kwds):")
        if spec.fields:
            out.append("        if args or kwds:")
            # every field positionally, the usual call (SetBoolResponse(True, "ok")): no
            # per-field setattr; anything else, errors included, by genpy's rules
            out.append(f"            if not kwds and len(args) == {len(attrs)}:")
            out.append(f"                {', '.join(f'self.{a}' for a in attrs)}, = args")
            out.append("            else:")
            out.append("                _init_fields(self, args, kwds)")
            for f, attr in zip(spec.fields, attrs):
                out.append(f"            if self.{attr} is None:")
                out.append(f"                self.{attr} = {default_value(f.type, f.base_type, f.is_array, f.array_len)}")
            out.append("        else:")
            for f, attr in zip(spec.fields, attrs):
                out.append(f"            self.{attr} = {default_value(f.type, f.base_type, f.is_array, f.array_len)}")
        else:
            out.append("        _init_fields(self, args, kwds)")
        out.append("")
        out.append("    def _serialize_parts(self, append):")
        out.append('        """Append the wire form of this message, in pieces, with ``append``."""')
        out.extend(ser.lines or ["        pass"])
    out.append("")
    out.append("    def _deserialize_from(self, view, end):")
    out.append('        """Fill this message from ``view[end:]``; returns the offset after it."""')
    out.extend(de.lines)
    out.append("        return end")
    out.append("")
    if fresh.lines == de.lines:
        out.append("    _deserialize_fresh = _deserialize_from  # no embedded message or time to build")
    else:
        out.append("    def _deserialize_fresh(self, view, end):")
        out.append('        """As _deserialize_from, into a message made by __new__: every field is new."""')
        out.extend(fresh.lines)
        out.append("        return end")
    out.append("")
    return "\n".join(_module_head(spec, "\n".join(out), bool(deps)) + out)


def _origin(spec: MsgSpec) -> str:
    """Where the definition came from, the same on every machine: ``pkg/msg/Name.msg``."""
    if not spec.filename:
        return "a message definition text"
    parts = spec.filename.replace("\\", "/").split("/")
    return "/".join(parts[-3:])


def _module_head(spec: MsgSpec, body: str, has_deps: bool) -> List[str]:
    """The module's first lines: where it came from and exactly the helpers ``body`` uses."""
    used = [alias for alias in EXPORTS if re.search(rf"\b{alias}\b", body)]
    head = [f"# Message class for {spec.full_name}, generated by minros.msgs from {_origin(spec)}."]
    if used:  # underscored aliases: a field or message named Time or Struct cannot clash
        head.append("from minros.msgs.runtime import (")
        head += [f"    {EXPORTS[alias]} as {alias}," for alias in used]
        head.append(")")
    if has_deps:
        head += [
            'if "_load" not in globals():  # run on its own, not compiled by a message registry',
            "    from minros.msgs import get_message_class as _load",
        ]
    return head


def _text_literal(text: str, indent: int) -> str:
    """A readable literal for a multi-line text: one quoted line per source line."""
    lines = text.splitlines(keepends=True)
    if len(lines) <= 1:
        return repr(text)
    pad = " " * indent
    return "(\n" + "".join(f"{pad}{line!r}\n" for line in lines) + " " * (indent - 4) + ")"


def _collect_deps(type_name: str, get_spec: GetSpec, out: List[str]) -> None:
    if type_name in out:
        return
    out.append(type_name)
    for f in get_spec(type_name).fields:
        if not f.is_builtin:
            _collect_deps(f.base_type, get_spec, out)
