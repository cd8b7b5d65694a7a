"""Plain CDR (XCDR1, little endian) for ROS 2 types: a class, serializer and deserializer per
type, generated as readable Python source and compiled once.

The wire rules (OMG CDR as ROS 2's rmw implementations write it):

* a 4-byte encapsulation header ``00 01 00 00`` (CDR_LE), then the body; alignment is relative
  to the start of the body;
* each primitive is aligned to its size (1, 2, 4, 8); ``bool`` is one byte, 0 or 1;
* ``string``: uint32 length counting a terminating NUL, the UTF-8 bytes, the NUL;
  ``wstring``: uint32 count of UTF-16 code units, each written as a uint32 (rmw_fastrtps);
* a sequence (``T[]``, ``T[<=N]``): uint32 count, then the elements, aligned to the element
  only when there is one (an empty ``float64[]`` adds no padding); a fixed array ``T[N]``: the
  elements; a nested struct: its members in order, nothing around them.

Readers ignore trailing bytes: rmw_fastrtps pads fixed-size types to a multiple of 4, and
rclpy's ``serialize_message`` may return bytes after the message. Writers add none.

As in :mod:`minros.msgs.codegen`, nested structs are expanded in place, so fixed-size fields in a
row (across nesting levels, the next length prefix included) are packed and unpacked by one
precompiled ``struct.Struct`` whose format holds the alignment padding. Padding is known when
code is generated as long as the position is known modulo the alignment; after a string or a
sequence it is computed at run time (``-pos & 7``). Every count and length is checked against
the bytes that remain before anything is allocated. ``uint8``/``byte``/``char`` arrays are
``bytes``, other numeric arrays ``array.array`` (read and written without a Python loop), ``bool``
arrays lists; a scalar ``byte`` is an int (rclpy's 1-byte ``bytes`` is accepted too).
"""

from __future__ import annotations

import keyword
import linecache
import re
import struct
from typing import Any, Callable, Dict, List, Mapping, Optional, Tuple

from minros.exceptions import DeserializationError, SerializationError
from minros.msgs.spec import MsgSpecError

from .cdrruntime import EXPORTS, Struct2
from .model import (
    ARRAY,
    BOUNDED,
    PRIMITIVE_SIZE,
    STRUCT_CODE,
    FieldType,
    MessageType,
)

GetType = Callable[[str], MessageType]
_OCTETS = ("uint8", "byte", "char")


def python_name(name: str) -> str:
    """The attribute of a member (Python keywords get a trailing ``_``)."""
    return name + "_" if keyword.iskeyword(name) else name


def class_ref(type_name: str) -> str:
    """The module-level name bound to the class of ``pkg/msg/Name``."""
    return "_" + type_name.replace("/", "__")


class Phase:
    """What generated code knows of the position: ``pos % m == r`` (m = 1, 2, 4 or 8)."""

    __slots__ = ("m", "r")

    def __init__(self, m: int = 8, r: int = 0) -> None:
        self.m, self.r = m, r

    def copy(self) -> Phase:
        return Phase(self.m, self.r)

    def known(self, align: int) -> bool:
        return self.m >= align

    def pad(self, align: int) -> int:
        return -self.r % align

    def advance(self, n: int) -> None:
        self.r = (self.r + n) % self.m

    def aligned(self, align: int) -> None:
        """After run-time alignment to ``align``."""
        if self.m < align:
            self.m, self.r = align, 0
        else:
            self.advance(self.pad(align))

    def forget(self, m: int) -> None:
        """Keep only what is known modulo ``m``."""
        if m < self.m:
            self.m = m
            self.r %= m

    def after_sequence(self, size: int) -> None:
        """After the elements of a sequence of primitives of ``size`` bytes (count unknown;
        the count itself left the position 4-aligned)."""
        if size == 8 and self.m == 8 and self.r == 0:
            return
        self.forget(min(size, 4))
        self.r = 0


def min_size(struct_: MessageType, get_type: GetType) -> int:
    """The fewest body bytes an instance takes (alignment aside): bounds counts before
    allocating."""
    total = 0
    for f in struct_.fields:
        t = f.type
        if t.is_sequence:
            total += 4
            continue
        if t.is_string:
            one = 4
        elif t.is_primitive:
            one = PRIMITIVE_SIZE[t.base]
        else:
            one = min_size(get_type(t.base), get_type)
        total += one * (t.size if t.kind == ARRAY else 1)
    return total


def check_acyclic(name: str, get_type: GetType) -> List[str]:
    """Every struct ``name`` nests, each once (depth first); raises on a recursive definition."""
    out: List[str] = []

    def visit(current: str, stack: Tuple[str, ...]) -> None:
        for dep in get_type(current).dependencies():
            if dep in stack:
                struct_ = get_type(current)
                raise MsgSpecError(f"recursive type: {' -> '.join(stack + (dep,))}",
                                   struct_.origin or struct_.name)
            if dep not in out:
                out.append(dep)
            visit(dep, stack + (dep,))

    visit(name, (name,))
    return out


class _Gen:
    """Shared machinery: indented lines, struct formats, the known position phase."""

    def __init__(self, structs: Dict[str, str], get_type: GetType, type_name: str) -> None:
        self.lines: List[str] = []
        self.structs = structs
        self.get_type = get_type
        self.type_name = type_name
        self.counter = 0
        self.phase = Phase()
        self.run_fmt = ""
        self.run_size = 0
        self.run: List[str] = []

    def emit(self, ind: int, line: str) -> None:
        self.lines.append("    " * ind + line)

    def tmp(self, prefix: str) -> str:
        self.counter += 1
        return f"{prefix}{self.counter}"

    def struct(self, fmt: str) -> str:
        name = "_S_" + fmt.replace("?", "o")
        self.structs[fmt] = name
        return name

    def fixed(self, ind: int, code: str, target: str, size: int) -> None:
        """One fixed-size primitive in the current run, aligned."""
        if not self.phase.known(size):
            self.flush(ind)
            self.runtime_align(ind, size)
        pad = self.phase.pad(size)
        if pad:
            self.run_fmt += f"{pad}x" if pad > 1 else "x"
            self.run_size += pad
            self.phase.advance(pad)
        self.run_fmt += code
        self.run_size += size
        self.run.append(target)
        self.phase.advance(size)

    def align(self, ind: int, size: int, var: str) -> None:
        """Align ``var`` (the position) to ``size``, statically when the phase allows."""
        if size == 1:
            return
        if self.phase.known(size):
            pad = self.phase.pad(size)
            if pad:
                self.pad_lines(ind, str(pad))
                self.phase.advance(pad)
        else:
            self.runtime_align(ind, size)

    def runtime_align(self, ind: int, size: int) -> None:
        raise NotImplementedError

    def pad_lines(self, ind: int, pad: str) -> None:
        raise NotImplementedError

    def flush(self, ind: int) -> None:
        raise NotImplementedError

    def loop_phase(self) -> Phase:
        return Phase(1, 0)


class _SerializerGen(_Gen):
    """``pos = write(m, out, pos)``: appends the body bytes of ``m`` to ``out``."""

    def flush(self, ind: int) -> None:
        if not self.run:
            return
        name = self.struct(self.run_fmt)
        self.emit(ind, f"out.append({name}.pack({', '.join(self.run)}))")
        self.emit(ind, f"pos += {self.run_size}")
        self.run, self.run_fmt, self.run_size = [], "", 0

    def runtime_align(self, ind: int, size: int) -> None:
        self.emit(ind, f"k = -pos & {size - 1}")
        self.emit(ind, "if k:")
        self.emit(ind + 1, "out.append(_ZEROS[k])")
        self.emit(ind + 1, "pos += k")
        self.phase.aligned(size)

    def pad_lines(self, ind: int, pad: str) -> None:
        self.emit(ind, f"out.append(_ZEROS[{pad}])")
        self.emit(ind, f"pos += {pad}")

    def piece(self, ind: int, expr: str, size: str) -> None:
        self.flush(ind)
        self.emit(ind, f"out.append({expr})")
        self.emit(ind, f"pos += {size}")

    def check_len(self, ind: int, var: str, t: FieldType, fpath: str) -> None:
        if t.kind == ARRAY:
            self.emit(ind, f"if len({var}) != {t.size}:")
            self.emit(ind + 1, f"raise _bad_length({self.type_name!r}, {fpath!r}, {t.size}, "
                               f"len({var}))")
        elif t.kind == BOUNDED:
            self.emit(ind, f"if len({var}) > {t.size}:")
            self.emit(ind + 1, f"raise _bad_length({self.type_name!r}, {fpath!r}, {t.size}, "
                               f"len({var}), True)")

    def string(self, ind: int, expr: str, t: FieldType, fpath: str) -> None:
        var = self.tmp("_s")
        if t.base == "wstring":
            count = self.tmp("_n")
            self.emit(ind, f"{count}, {var} = _encode_wstring({expr})")
            if t.string_bound:
                self.emit(ind, f"if {count} > {t.string_bound}:")
                self.emit(ind + 1, f"raise _bad_length({self.type_name!r}, {fpath!r}, "
                                   f"{t.string_bound}, {count}, True)")
            self.fixed(ind, "I", count, 4)
            self.piece(ind, var, f"len({var})")
        else:
            self.emit(ind, f"{var} = _encode_string({expr})")
            if t.string_bound:
                self.emit(ind, f"if len({var}) > {t.string_bound}:")
                self.emit(ind + 1, f"raise _bad_length({self.type_name!r}, {fpath!r}, "
                                   f"{t.string_bound}, len({var}), True)")
            self.fixed(ind, "I", f"len({var}) + 1", 4)
            self.piece(ind, var, f"len({var})")
            self.emit(ind, "out.append(_ZEROS[1])")
            self.emit(ind, "pos += 1")
        self.phase.forget(1)

    def fields(self, struct_: MessageType, obj: str, path: str, ind: int) -> None:
        for f in struct_.fields:
            attr = python_name(f.name)
            expr = f"{obj}.{attr}"
            fpath = path + f.name
            t = f.type
            if not t.is_array:
                if t.is_string:
                    self.string(ind, expr, t, fpath)
                elif t.is_primitive:
                    value = f"_byte_value({expr})" if t.base == "byte" else expr
                    self.fixed(ind, STRUCT_CODE[t.base], value, PRIMITIVE_SIZE[t.base])
                else:
                    var = self.tmp("_m")
                    self.emit(ind, f"{var} = {expr}")
                    self.fields(self.get_type(t.base), var, fpath + ".", ind)
                continue
            var = self.tmp("_a")
            if t.base in _OCTETS:
                self.emit(ind, f"{var} = _as_octets({expr})")
                self.check_len(ind, var, t, fpath)
                if t.is_sequence:
                    self.fixed(ind, "I", f"len({var})", 4)
                self.piece(ind, var, str(t.size) if t.kind == ARRAY else f"len({var})")
                if t.kind == ARRAY:
                    self.phase.advance(t.size)
                else:
                    self.phase.forget(1)
            elif t.is_primitive and not t.is_string:
                size = PRIMITIVE_SIZE[t.base]
                data = self.tmp("_d")
                if t.base == "bool":
                    self.emit(ind, f"{data} = _pack_bools({expr})")
                    self.emit(ind, f"{var} = len({data})")
                else:
                    self.emit(ind, f"{data} = _pack_numbers({STRUCT_CODE[t.base]!r}, {expr})")
                    self.emit(ind, f"{var} = len({data}) // {size}" if size > 1
                              else f"{var} = len({data})")
                self.check_count(ind, var, t, fpath)
                if t.kind == ARRAY:
                    self.flush(ind)
                    self.align(ind, size, "pos")
                    self.piece(ind, data, str(t.size * size))
                    self.phase.advance(t.size * size)
                else:
                    self.fixed(ind, "I", var, 4)
                    self.flush(ind)
                    if size == 8:
                        self.emit(ind, f"if {var}:")
                        before = self.phase.copy()
                        self.align(ind + 1, 8, "pos")
                        self.emit(ind + 1, "pass")
                        self.phase = before
                    self.piece(ind, data, f"len({data})")
                    self.phase.after_sequence(size)
            else:
                self.emit(ind, f"{var} = {expr}")
                self.check_len(ind, var, t, fpath)
                if t.is_sequence:
                    self.fixed(ind, "I", f"len({var})", 4)
                self.flush(ind)
                item = self.tmp("_e")
                self.emit(ind, f"for {item} in {var}:")
                self.phase = self.loop_phase()
                if t.is_string:
                    self.string(ind + 1, item, t.element(), fpath + "[]")
                else:
                    self.fields(self.get_type(t.base), item, fpath + "[].", ind + 1)
                self.flush(ind + 1)
                self.emit(ind + 1, "pass")
                self.phase = Phase(1, 0)

    def check_count(self, ind: int, var: str, t: FieldType, fpath: str) -> None:
        if t.kind == ARRAY:
            self.emit(ind, f"if {var} != {t.size}:")
            self.emit(ind + 1, f"raise _bad_length({self.type_name!r}, {fpath!r}, {t.size}, "
                               f"{var})")
        elif t.kind == BOUNDED:
            self.emit(ind, f"if {var} > {t.size}:")
            self.emit(ind + 1, f"raise _bad_length({self.type_name!r}, {fpath!r}, {t.size}, "
                               f"{var}, True)")


class _DeserializerGen(_Gen):
    """``p = read(o, v, p)``: fills ``o`` (made by ``__new__``) from the body view ``v``."""

    def __init__(self, structs: Dict[str, str], get_type: GetType, type_name: str) -> None:
        super().__init__(structs, get_type, type_name)
        self.post: List[str] = []

    def flush(self, ind: int) -> None:
        if not self.run:
            return
        name = self.struct(self.run_fmt)
        targets = ", ".join(self.run) + ("," if len(self.run) == 1 else "")
        self.emit(ind, f"{targets} = {name}.unpack_from(v, p)")
        self.emit(ind, f"p += {self.run_size}")
        self.run, self.run_fmt, self.run_size = [], "", 0

    def runtime_align(self, ind: int, size: int) -> None:
        self.emit(ind, f"p += -p & {size - 1}")
        self.phase.aligned(size)

    def pad_lines(self, ind: int, pad: str) -> None:
        self.emit(ind, f"p += {pad}")

    def length(self, ind: int) -> str:
        var = self.tmp("_n")
        self.fixed(ind, "I", var, 4)
        self.flush(ind)
        return var

    def need(self, ind: int, nbytes: str, fpath: str) -> None:
        self.emit(ind, f"if {nbytes} > len(v) - p:")
        self.emit(ind + 1, f"raise _overrun({self.type_name!r}, {fpath!r}, {nbytes}, len(v) - p)")

    def bound(self, ind: int, count: str, bound: int, fpath: str) -> None:
        self.emit(ind, f"if {count} > {bound}:")
        self.emit(ind + 1, f"raise _over_bound({self.type_name!r}, {fpath!r}, {count}, {bound})")

    def string(self, ind: int, target: str, t: FieldType, fpath: str) -> None:
        n = self.length(ind)
        if t.base == "wstring":
            self.need(ind, f"4 * {n}", fpath)
            if t.string_bound:
                self.bound(ind, n, t.string_bound, fpath)
            self.emit(ind, f"{target} = _decode_wstring(v, p, {n})")
            self.emit(ind, f"p += 4 * {n}")
        else:
            self.need(ind, n, fpath)
            if t.string_bound:
                self.bound(ind, f"{n} - 1", t.string_bound, fpath)
            self.emit(ind, f"{target} = str(v[p:p + {n} - 1], 'utf-8', 'replace')")
            self.emit(ind, f"p += {n}")
        self.phase.forget(1)

    def fields(self, struct_: MessageType, obj: str, path: str, ind: int) -> None:
        for f in struct_.fields:
            target = f"{obj}.{python_name(f.name)}"
            fpath = path + f.name
            t = f.type
            if not t.is_array:
                if t.is_string:
                    self.string(ind, target, t, fpath)
                elif t.is_primitive:
                    self.fixed(ind, STRUCT_CODE[t.base], target, PRIMITIVE_SIZE[t.base])
                else:
                    var = self.tmp("_m")
                    self.emit(ind, f"{var} = {target} = _new({class_ref(t.base)})")
                    self.fields(self.get_type(t.base), var, fpath + ".", ind)
                continue
            if t.kind == ARRAY:
                self.flush(ind)
                count = str(t.size)
            else:
                count = self.length(ind)
                if t.kind == BOUNDED:
                    self.bound(ind, count, t.size, fpath)
            if t.base in _OCTETS:
                self.need(ind, count, fpath)
                self.emit(ind, f"{target} = bytes(v[p:p + {count}])")
                self.emit(ind, f"p += {count}")
                if t.kind == ARRAY:
                    self.phase.advance(t.size)
                else:
                    self.phase.forget(1)
            elif t.is_primitive and not t.is_string:
                size = PRIMITIVE_SIZE[t.base]
                nbytes = f"{count} * {size}" if size > 1 else count
                if t.kind == ARRAY:
                    self.align(ind, size, "p")
                elif size == 8:
                    self.emit(ind, f"if {count}:")
                    before = self.phase.copy()
                    self.align(ind + 1, 8, "p")
                    self.emit(ind + 1, "pass")
                    self.phase = before
                self.need(ind, nbytes, fpath)
                if t.base == "bool":
                    self.emit(ind, f"{target} = _bools(v, p, {count})")
                else:
                    self.emit(ind, f"{target} = _numbers({STRUCT_CODE[t.base]!r}, v, p, {count})")
                self.emit(ind, f"p += {nbytes}")
                if t.kind == ARRAY:
                    self.phase.advance(t.size * size)
                else:
                    self.phase.after_sequence(size)
            else:
                least = 4 if t.is_string else min_size(self.get_type(t.base), self.get_type)
                self.emit(ind, f"if {count} * {least} > len(v) - p:")
                self.emit(ind + 1, f"raise _too_many({self.type_name!r}, {fpath!r}, {count}, "
                                   f"len(v) - p)")
                items = self.tmp("_l")
                self.emit(ind, f"{items} = {target} = []")
                self.emit(ind, f"for _ in range({count}):")
                self.phase = self.loop_phase()
                var = self.tmp("_e")
                if t.is_string:
                    self.string(ind + 1, var, t.element(), fpath + "[]")
                else:
                    self.emit(ind + 1, f"{var} = _new({class_ref(t.base)})")
                    self.fields(self.get_type(t.base), var, fpath + "[].", ind + 1)
                    self.flush(ind + 1)
                self.emit(ind + 1, f"{items}.append({var})")
                self.phase = Phase(1, 0)


def default_expr(t: FieldType, default: Any) -> str:
    """The Python expression of a member's initial value (its default, or zero)."""
    if not t.is_array:
        if default is not None:
            return repr(default)
        if t.is_string:
            return "''"
        if t.base == "bool":
            return "False"
        if t.base in ("float32", "float64"):
            return "0.0"
        if t.is_primitive:
            return "0"
        return f"{class_ref(t.base)}()"
    if t.base in _OCTETS:
        if default is not None:
            return repr(bytes(default))
        return f"bytes({t.size})" if t.kind == ARRAY else "b''"
    if t.is_primitive and not t.is_string and t.base != "bool":
        code = STRUCT_CODE[t.base]
        if default is not None:
            return f"_new_array({code!r}, {tuple(default)!r})"
        if t.kind == ARRAY:
            return f"_new_array({code!r}, ({'0.0' if code in 'fd' else '0'},) * {t.size})"
        return f"_new_array({code!r})"
    if t.is_primitive:  # bool, string
        if default is not None:
            return repr(list(default))
        if t.kind == ARRAY:
            return f"[{'False' if t.base == 'bool' else repr('')}] * {t.size}"
        return "[]"
    if t.kind == ARRAY:
        return f"[{class_ref(t.base)}() for _ in range({t.size})]"
    return "[]"


def generate_source(name: str, get_type: GetType) -> str:
    """The Python source of the codec module of struct ``name``: its class ``Name`` and the
    functions ``write(m, out, pos) -> pos`` and ``read(o, v, p) -> p``."""
    struct_ = get_type(name)
    deps = check_acyclic(name, get_type)
    structs: Dict[str, str] = {}
    ser = _SerializerGen(structs, get_type, name)
    ser.fields(struct_, "m", "", 1)
    ser.flush(1)
    de = _DeserializerGen(structs, get_type, name)
    de.fields(struct_, "o", "", 1)
    de.flush(1)

    cls = struct_.short_name
    attrs = tuple(python_name(f.name) for f in struct_.fields)
    body: List[str] = []
    if deps:
        body += ["", "# classes of the nested types"]
        body += [f"{class_ref(d)} = _load({d!r})" for d in deps]
    if structs:
        body += ["", "# fixed-size runs of members with their alignment padding ('x')"]
        body += [f"{n} = _Struct({'<' + fmt!r})" for fmt, n in sorted(structs.items(),
                                                                       key=lambda kv: kv[1])]
    body += ["", "", f"class {cls}(_Struct2):", f'    """{name}."""', "",
             f"    __slots__ = {attrs!r}", f"    _type = {name!r}",
             f"    _fields = {tuple((f.name, f.type.msg_text()) for f in struct_.fields)!r}"]
    for c in struct_.constants:
        body.append(f"    {c.name} = {c.value!r}")
    params = ", ".join(f"{a}=None" for a in attrs)
    body += ["", f"    def __init__(self, {params}):"]
    for f, a in zip(struct_.fields, attrs):
        body.append(f"        self.{a} = {default_expr(f.type, f.default)} if {a} is None "
                    f"else {a}")
    body += ["", "", "def write(m, out, pos):",
             f'    """Append the CDR body of a {cls} to ``out``; returns the new position."""']
    body += ser.lines
    body += ["    return pos", "", "", "def read(o, v, p):",
             f'    """Fill ``o`` (a {cls} made by __new__) from the CDR body ``v`` at ``p``."""']
    body += de.lines
    body += ["    return p", ""]
    text = "\n".join(body)
    used = [alias for alias in EXPORTS if re.search(rf"\b{alias}\b", text)]
    head = [f"# CDR codec for {name}, generated by minros.ros2.types.cdr."]
    if used:
        head.append("from minros.ros2.types.cdrruntime import (")
        head += [f"    {EXPORTS[alias]} as {alias}," for alias in used]
        head.append(")")
    if deps:
        head += ['if "_load" not in globals():  # run on its own, not compiled by a registry',
                 "    from minros.ros2.types import registry as _registry",
                 "    def _load(name):",
                 "        return _registry().codec(name).cls"]
    return "\n".join(head + body)


class Codec:
    """CDR for one struct type: ``cls`` (its Python class), ``serialize``, ``deserialize``."""

    def __init__(self, struct_: MessageType, source: str, namespace: Dict[str, Any],
                 get_codec: Callable[[str], Codec]) -> None:
        self.struct = struct_
        self.name = struct_.name
        self.source = source
        self.cls: type = namespace[struct_.short_name]
        self._write = namespace["write"]
        self._read = namespace["read"]
        self._get_codec = get_codec

    def serialize(self, value: Any) -> bytes:
        """The CDR bytes (with the encapsulation header) of ``value``: an instance of
        :attr:`cls`, any object with the members as attributes, or a dict of them."""
        if isinstance(value, Mapping):
            value = self.from_dict(value)
        out: List[Any] = [b"\x00\x01\x00\x00"]
        try:
            self._write(value, out, 0)
        except SerializationError:
            raise
        except (struct.error, TypeError, ValueError, AttributeError, OverflowError) as exc:
            raise SerializationError(f"{self.name}: cannot serialize: {exc}") from None
        return b"".join(out)

    def deserialize(self, data: Any) -> Any:
        """An instance of :attr:`cls` from CDR bytes (header included). Raises
        :class:`DeserializationError` naming the field on truncated or inconsistent data."""
        view = memoryview(data)
        if view.ndim != 1 or view.itemsize != 1:
            view = view.cast("B")
        if len(view) < 4:
            raise DeserializationError(f"{self.name}: {len(view)} bytes are not CDR (the "
                                       f"4-byte encapsulation header is missing)")
        if view[0] != 0 or view[1] not in (0, 1):
            raise DeserializationError(f"{self.name}: encapsulation {bytes(view[:2]).hex()} "
                                       f"is not plain CDR (expected 0001, little endian)")
        if view[1] == 0:
            raise DeserializationError(f"{self.name}: big-endian CDR (encapsulation 0000) is "
                                       f"not supported")
        obj: Any = object.__new__(self.cls)
        try:
            self._read(obj, view[4:], 0)
        except DeserializationError:
            raise
        except (struct.error, ValueError, OverflowError) as exc:
            raise DeserializationError(f"{self.name}: truncated or invalid CDR data: "
                                       f"{exc}") from None
        return obj

    def from_dict(self, value: Mapping[str, Any]) -> Any:
        """An instance of :attr:`cls` from a dict (nested dicts become nested instances)."""
        unknown = set(value) - {f.name for f in self.struct.fields}
        if unknown:
            raise SerializationError(f"{self.name} has no field(s) {', '.join(sorted(unknown))}")
        kwargs: Dict[str, Any] = {}
        for f in self.struct.fields:
            if f.name not in value:
                continue
            item = value[f.name]
            if f.type.is_nested:
                codec = self._get_codec(f.type.base)
                if f.type.is_array:
                    item = [codec.from_dict(e) if isinstance(e, Mapping) else e for e in item]
                elif isinstance(item, Mapping):
                    item = codec.from_dict(item)
            kwargs[python_name(f.name)] = item
        return self.cls(**kwargs)

    def to_dict(self, obj: Any) -> Dict[str, Any]:
        """A dict of ``obj``'s members (nested structs as dicts, arrays as lists)."""
        out: Dict[str, Any] = {}
        for f in self.struct.fields:
            item = getattr(obj, python_name(f.name))
            if f.type.is_nested:
                codec = self._get_codec(f.type.base)
                item = [codec.to_dict(e) for e in item] if f.type.is_array else codec.to_dict(item)
            elif f.type.is_array and not isinstance(item, (bytes, bytearray)):
                item = list(item)
            out[f.name] = item
        return out

    def __repr__(self) -> str:
        return f"<CDR codec {self.name}>"


def build_codec(name: str, get_type: GetType,
                get_codec: Optional[Callable[[str], Codec]] = None) -> Codec:
    """Generate and compile the codec of struct ``name`` (nested types through ``get_codec``)."""
    struct_ = get_type(name)
    if get_codec is None:
        cache: Dict[str, Codec] = {}

        def get_codec(dep: str) -> Codec:
            found = cache.get(dep)
            if found is None:
                found = cache[dep] = build_codec(dep, get_type, get_codec)
            return found

    source = generate_source(name, get_type)
    filename = f"<minros ros2 cdr {name}>"
    linecache.cache[filename] = (len(source), None, source.splitlines(True), filename)
    loader = get_codec
    namespace: Dict[str, Any] = {"_load": lambda dep: loader(dep).cls,
                                 "__name__": "minros.ros2.types.generated"}
    exec(compile(source, filename, "exec"), namespace)
    return Codec(struct_, source, namespace, loader)


__all__ = ["Codec", "Phase", "Struct2", "build_codec", "generate_source", "min_size",
           "python_name"]
