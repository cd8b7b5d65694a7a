"""Byte converters between ROS 1 serialization and CDR, generated per type pair.

A :class:`Transcoder` turns the bytes of a ROS 1 message into the CDR bytes of its ROS 2
counterpart and back, without making message objects: the live bridge runs it on every message
and bag conversion on every record. Its two functions are generated as Python source from a
:class:`~minros.ros2.types.mapping.MessageMapping` (print ``transcoder.source``) and walk the
ROS 1 fields in order, reading one side and writing the other:

* fixed-size fields in a row are unpacked by one ``struct`` from the source and packed by one
  into the destination, the CDR side's alignment padding in its format; values are carried
  bit for bit (integers and floats as unsigned integers of their size, so a NaN or a time after
  2038 comes back the same), only ``bool`` is read as truth and written 0/1;
* strings, arrays of numbers and byte arrays are slices of the input (a ``memoryview``) handed to
  the output list, which is joined once: a 6 MB image costs one copy of its pixels;
* arrays of structs whose layout is the same on both sides (``Point[]``, ``Pose[]``, ``time[]``)
  are one slice too; others are converted element by element;
* ROS 1 fields ROS 2 lacks are skipped (and written as zeros coming back; a top-level Header's
  ``seq`` is the ``seq`` argument), ROS 2 members ROS 1 lacks are written with their default
  (and skipped coming back).

Every count and length is checked against the bytes that remain before it is used; a ROS 1
message must be consumed exactly, a CDR one may carry padding after it.
"""

from __future__ import annotations

import linecache
import re
import struct
from typing import Any, Callable, Dict, List, Optional, Tuple

from minros.exceptions import DeserializationError, SerializationError
from minros.msgs.message import MAX_EMPTY_ELEMENTS
from minros.msgs.spec import Field as Ros1Field
from minros.msgs.spec import MsgSpec

from .cdr import Phase, min_size
from .model import ARRAY, BOUNDED, PRIMITIVE_SIZE, STRUCT_CODE, FieldType

_ROS1_SIZE = {"int8": 1, "uint8": 1, "byte": 1, "char": 1, "bool": 1, "int16": 2, "uint16": 2,
              "int32": 4, "uint32": 4, "int64": 8, "uint64": 8, "float32": 4, "float64": 8}
_COPY_CODE = {1: "B", 2: "H", 4: "I", 8: "Q"}
_OCTETS = ("uint8", "byte", "char")
#: bool bytes as 0/1 (``bytes.translate``)
BOOL_TABLE = bytes([0] + [1] * 255)
UNROLL = 16  # fixed arrays of structs longer than this become loops


def copy_code(base: str) -> str:
    """The struct code that carries a fixed-size primitive bit for bit (bool as truth)."""
    return "?" if base == "bool" else _COPY_CODE[PRIMITIVE_SIZE[base]]


class _Chan:
    """One side of a conversion: ROS 1 (packed) or CDR (aligned), read (``v``, ``p``) or
    written (``out``, ``pos``). Fixed-size items collect in a run flushed as one struct call."""

    def __init__(self, gen: _Gen, cdr: bool, reading: bool) -> None:
        self.gen = gen
        self.cdr = cdr
        self.reading = reading
        self.phase = Phase()
        self.fmt = ""
        self.size = 0
        self.items: List[str] = []

    def emit(self, ind: int, line: str) -> None:
        self.gen.emit(ind, line)

    def _pad(self, n: int) -> None:
        if n:
            self.fmt += f"{n}x" if n > 1 else "x"
            self.size += n
            if self.cdr:
                self.phase.advance(n)

    def fixed(self, ind: int, code: str, item: Optional[str]) -> None:
        """A fixed-size primitive: read into ``item`` (None: skipped) or write ``item``."""
        size = struct.calcsize("<" + code)
        if self.cdr:
            if not self.phase.known(size):
                self.flush(ind)
                self.runtime_align(ind, size)
            self._pad(self.phase.pad(size))
        if item is None:
            self._pad(size)
            return
        self.fmt += code
        self.size += size
        self.items.append(item)
        if self.cdr:
            self.phase.advance(size)

    def zeros(self, n: int) -> None:
        """``n`` bytes of zeros written (or skipped when reading), no alignment."""
        self._pad(n)

    def flush(self, ind: int) -> None:
        if not self.reading:
            self.gen.src.flush(ind)
        if not self.size:
            return
        name = self.gen.struct(self.fmt)
        if self.reading:
            if self.items:
                targets = ", ".join(self.items) + ("," if len(self.items) == 1 else "")
                self.emit(ind, f"{targets} = {name}.unpack_from(v, p)")
            self.emit(ind, f"p += {self.size}")
        else:
            self.emit(ind, f"out.append({name}.pack({', '.join(self.items)}))")
            if self.cdr:
                self.emit(ind, f"pos += {self.size}")
        self.fmt, self.size, self.items = "", 0, []

    def runtime_align(self, ind: int, align: int) -> None:
        if self.reading:
            self.emit(ind, f"p += -p & {align - 1}")
        else:
            self.emit(ind, f"k = -pos & {align - 1}")
            self.emit(ind, "if k:")
            self.emit(ind + 1, "out.append(_ZEROS[k])")
            self.emit(ind + 1, "pos += k")
        self.phase.aligned(align)

    def align(self, ind: int, align: int) -> None:
        if not self.cdr or align == 1:
            return
        if self.phase.known(align):
            self._pad(self.phase.pad(align))
        else:
            self.flush(ind)
            self.runtime_align(ind, align)

    def align_elements(self, ind: int, count: str, align: int) -> None:
        """Align to the elements of a sequence, only when it has any (the count itself left
        the position 4-aligned, so only 8-byte elements can need it)."""
        if not self.cdr or align < 8:
            return
        self.flush(ind)
        before = self.phase.copy()
        if self.phase.known(8):
            pad = self.phase.pad(8)
            if pad:
                self.emit(ind, f"if {count}:")
                if self.reading:
                    self.emit(ind + 1, f"p += {pad}")
                else:
                    self.emit(ind + 1, f"out.append(_ZEROS[{pad}])")
                    self.emit(ind + 1, f"pos += {pad}")
        else:
            self.emit(ind, f"if {count}:")
            self.runtime_align(ind + 1, 8)
        self.phase = before

    def piece(self, ind: int, expr: str, size: str) -> None:
        self.flush(ind)
        self.emit(ind, f"out.append({expr})")
        if self.cdr:
            self.emit(ind, f"pos += {size}")

    def skip(self, ind: int, nbytes: str) -> None:
        self.flush(ind)
        self.emit(ind, f"p += {nbytes}")

    def need(self, ind: int, nbytes: str, fpath: str) -> None:
        self.flush(ind)
        self.emit(ind, f"if {nbytes} > len(v) - p:")
        self.emit(ind + 1, f"raise _short({self.gen.src_kind!r}, {self.gen.type_name!r}, "
                           f"{fpath!r}, {nbytes}, len(v) - p)")

    def after(self, t: FieldType, constant_bytes: Optional[int] = None) -> None:
        """Update the phase after an array's elements were written or read."""
        if not self.cdr:
            return
        size = PRIMITIVE_SIZE.get(t.base, 1)
        if t.kind == ARRAY and constant_bytes is not None:
            self.phase.advance(constant_bytes)
        elif t.is_sequence and t.base in PRIMITIVE_SIZE and t.base not in _OCTETS:
            self.phase.after_sequence(size)
        else:
            self.phase.forget(1)

    def unknown(self) -> None:
        self.phase = Phase(1, 0)


class _Gen:
    """Generates one direction's function for a mapping."""

    def __init__(self, mapping: Any, to_cdr: bool, structs: Dict[str, str]) -> None:
        self.mapping = mapping
        self.mapper = mapping.mapper
        self.to_cdr = to_cdr
        self.type_name = mapping.ros1_type if to_cdr else mapping.ros2_type
        self.src_kind = "ROS 1" if to_cdr else "CDR"
        self.structs = structs
        self.lines: List[str] = []
        self.counter = 0
        self.src = _Chan(self, cdr=not to_cdr, reading=True)
        self.dst = _Chan(self, cdr=to_cdr, reading=False)

    def emit(self, ind: int, line: str) -> None:
        self.lines.append("    " * ind + line)

    def tmp(self, prefix: str) -> str:
        self.counter += 1
        return f"{prefix}{self.counter}"

    def struct(self, fmt: str) -> str:
        name = "_S_" + fmt.replace("?", "o")
        self.structs[fmt] = name
        return name

    def flush(self, ind: int) -> None:
        self.dst.flush(ind)  # flushes src first

    def loop_start(self) -> None:
        self.src.unknown()
        self.dst.unknown()

    # -- sizes ------------------------------------------------------------------------------------
    def ros1_min(self, base: str) -> int:
        if base in _ROS1_SIZE:
            return _ROS1_SIZE[base]
        if base == "string":
            return 4
        if base in ("time", "duration"):
            return 8
        spec = self.mapper.ros1_spec(base)
        return sum(self.ros1_field_min(f) for f in spec.fields)

    def ros1_field_min(self, f1: Ros1Field) -> int:
        if not f1.is_array:
            return self.ros1_min(f1.base_type)
        if f1.array_len is None:
            return 4
        return f1.array_len * self.ros1_min(f1.base_type)

    def ros1_fixed(self, f1: Ros1Field) -> bool:
        """Whether a ROS 1 field always takes the same number of bytes."""
        if f1.is_array and f1.array_len is None:
            return False
        base = f1.base_type
        if base in _ROS1_SIZE or base in ("time", "duration"):
            return True
        if base == "string":
            return False
        return all(self.ros1_fixed(f) for f in self.mapper.ros1_spec(base).fields)

    def cdr_min(self, t: FieldType) -> int:
        if t.is_string:
            return 4
        if t.is_primitive:
            return PRIMITIVE_SIZE[t.base]
        return min_size(self.mapper.ros2.message(t.base), self.mapper.ros2.message)

    # -- a mapped message -----------------------------------------------------------------------
    def message(self, m: Any, ind: int, fpath: str, seq: str) -> None:
        links = m.links
        paths = {link.ros1_path: i for i, link in enumerate(links) if link.ros1_path}
        done = [0]

        def until(index: int) -> None:
            for j in range(done[0], index):
                self.ros2_only(links[j], ind, fpath)
            done[0] = max(done[0], index + 1)

        def walk(spec: MsgSpec, prefix: Tuple[str, ...], seq_here: str) -> None:
            for f1 in spec.fields:
                path = prefix + (f1.name,)
                here = fpath + ".".join(path)
                header_seq = seq_here if (not prefix and f1.name == "header"
                                          and f1.base_type == "std_msgs/Header") else "0"
                if path in paths:
                    until(paths[path])
                    self.leaf(links[paths[path]], f1, ind, here, header_seq)
                elif any(p[:len(path)] == path for p in paths):
                    walk(self.mapper.ros1_spec(f1.base_type), path, header_seq)
                else:
                    value = seq_here if (spec.full_name == "std_msgs/Header"
                                         and f1.name == "seq") else None
                    self.ros1_only(f1, ind, here, value)

        walk(m.ros1, (), seq)
        until(len(links))

    def leaf(self, link: Any, f1: Ros1Field, ind: int, fpath: str, seq: str) -> None:
        t = link.ros2.type
        if link.nested is not None and not t.is_array:
            self.message(link.nested, ind, fpath + ".", seq)
            return
        if not t.is_array:
            if t.is_string:
                self.string(ind, t, fpath)
            else:
                var = self.tmp("_x")
                code = copy_code(t.base)
                self.src.fixed(ind, code, var)
                self.dst.fixed(ind, code, var)
            return
        if t.is_primitive and not t.is_string:
            self.numbers(ind, t, fpath)
            return
        count = self.count(ind, t, fpath)
        if t.is_string:
            self.need_elements(ind, count, 4, fpath)
        else:
            flat = flat_layout(link.nested, self)
            if flat is not None:
                size, align = flat
                self.need_elements(ind, count, size, fpath)
                self.src.align_elements(ind, count, align) if t.is_sequence \
                    else self.src.align(ind, align)
                self.dst.align_elements(ind, count, align) if t.is_sequence \
                    else self.dst.align(ind, align)
                nbytes = f"{count} * {size}"
                self.src.need(ind, nbytes, fpath)
                self.dst.piece(ind, f"v[p:p + {nbytes}]", nbytes)
                self.src.skip(ind, nbytes)
                for chan in (self.src, self.dst):
                    if chan.cdr:
                        if t.kind == ARRAY:
                            chan.phase.advance(t.size * size)
                        else:
                            chan.phase.forget(4 if align >= 4 and size % 4 == 0 else 1)
                return
            least = (self.ros1_min(f1.base_type) if self.to_cdr else self.cdr_min(t.element()))
            self.need_elements(ind, count, least, fpath)
        self.flush(ind)
        self.emit(ind, f"for _ in range({count}):")
        self.loop_start()
        if t.is_string:
            self.string(ind + 1, t.element(), fpath + "[]")
        else:
            self.message(link.nested, ind + 1, fpath + "[].", "0")
        self.flush(ind + 1)
        self.emit(ind + 1, "pass")
        self.loop_start()

    def count(self, ind: int, t: FieldType, fpath: str) -> str:
        """The element count of an array: read and written for a sequence, else the length."""
        if t.kind == ARRAY:
            return str(t.size)
        count = self.tmp("_n")
        self.src.fixed(ind, "I", count)
        self.src.flush(ind)
        if t.kind == BOUNDED and self.to_cdr:
            self.emit(ind, f"if {count} > {t.size}:")
            self.emit(ind + 1, f"raise _too_long({self.type_name!r}, {fpath!r}, {count}, "
                               f"{t.size})")
        self.dst.fixed(ind, "I", count)
        return count

    def need_elements(self, ind: int, count: str, least: int, fpath: str) -> None:
        if count.isdigit():
            return
        self.src.flush(ind)
        if least:
            self.emit(ind, f"if {count} * {least} > len(v) - p:")
        else:
            self.emit(ind, f"if {count} > {MAX_EMPTY_ELEMENTS}:")
        self.emit(ind + 1, f"raise _too_many({self.src_kind!r}, {self.type_name!r}, {fpath!r}, "
                           f"{count}, len(v) - p)")

    def string(self, ind: int, t: FieldType, fpath: str) -> None:
        n = self.tmp("_n")
        self.src.fixed(ind, "I", n)
        self.src.flush(ind)
        self.src.need(ind, n, fpath)
        if self.to_cdr:
            if t.string_bound:
                self.emit(ind, f"if {n} > {t.string_bound}:")
                self.emit(ind + 1, f"raise _too_long({self.type_name!r}, {fpath!r}, {n}, "
                                   f"{t.string_bound})")
            self.dst.fixed(ind, "I", f"{n} + 1")
            self.dst.piece(ind, f"v[p:p + {n}]", n)
            self.dst.piece(ind, "_ZEROS[1]", "1")
        else:
            k = self.tmp("_k")
            self.emit(ind, f"{k} = {n} - 1 if {n} else 0")
            self.dst.fixed(ind, "I", k)
            self.dst.piece(ind, f"v[p:p + {k}]", k)
        self.src.skip(ind, n)
        for chan in (self.src, self.dst):
            if chan.cdr:
                chan.phase.forget(1)

    def numbers(self, ind: int, t: FieldType, fpath: str) -> None:
        size = PRIMITIVE_SIZE[t.base]
        count = self.count(ind, t, fpath)
        if t.kind == ARRAY:
            self.src.align(ind, size)
            self.dst.align(ind, size)
        else:
            self.src.align_elements(ind, count, size)
            self.dst.align_elements(ind, count, size)
        nbytes = count if size == 1 else f"{count} * {size}"
        if count.isdigit():
            nbytes = str(int(count) * size)
        self.src.need(ind, nbytes, fpath)
        data = f"v[p:p + {nbytes}]"
        if t.base == "bool" and self.to_cdr:
            data = f"bytes({data}).translate(_BOOL_TABLE)"
        self.dst.piece(ind, data, nbytes)
        self.src.skip(ind, nbytes)
        constant = t.size * size if t.kind == ARRAY else None
        self.src.after(t, constant)
        self.dst.after(t, constant)

    # -- one side only ----------------------------------------------------------------------------
    def ros1_only(self, f1: Ros1Field, ind: int, fpath: str, value: Optional[str]) -> None:
        """A ROS 1 field with no ROS 2 partner: skipped (to CDR) or zeros (to ROS 1)."""
        if not self.to_cdr:
            if value is not None and value != "0":
                self.dst.fixed(ind, "I", value)
            else:
                self.dst.zeros(self.ros1_field_min(f1))
            return
        if self.ros1_fixed(f1):
            self.src.zeros(self.ros1_field_min(f1))
            return
        self.ros1_skip(f1, ind, fpath)

    def ros1_skip(self, f1: Ros1Field, ind: int, fpath: str) -> None:
        base = f1.base_type
        if f1.is_array:
            if f1.array_len is None:
                count = self.tmp("_n")
                self.src.fixed(ind, "I", count)
                self.src.flush(ind)
            else:
                count = str(f1.array_len)
            if base in _ROS1_SIZE or base in ("time", "duration"):
                nbytes = f"{count} * {self.ros1_min(base)}"
                self.src.need(ind, nbytes, fpath)
                self.src.skip(ind, nbytes)
                return
            self.need_elements(ind, count, self.ros1_min(base), fpath)
            self.src.flush(ind)
            self.emit(ind, f"for _ in range({count}):")
            self.ros1_skip(Ros1Field(f1.name, base), ind + 1, fpath + "[]")
            self.src.flush(ind + 1)
            self.emit(ind + 1, "pass")
            return
        if base == "string":
            n = self.tmp("_n")
            self.src.fixed(ind, "I", n)
            self.src.need(ind, n, fpath)
            self.src.skip(ind, n)
            return
        if base in _ROS1_SIZE or base in ("time", "duration"):
            self.src.zeros(self.ros1_min(base))
            return
        for f in self.mapper.ros1_spec(base).fields:
            if self.ros1_fixed(f):
                self.src.zeros(self.ros1_field_min(f))
            else:
                self.ros1_skip(f, ind, f"{fpath}.{f.name}")

    def ros2_only(self, link: Any, ind: int, fpath: str) -> None:
        """A ROS 2 member with no ROS 1 partner: its default (to CDR) or skipped (to ROS 1)."""
        f2 = link.ros2
        if self.to_cdr:
            self.cdr_default(f2.type, f2.default, ind, fpath + f2.name)
        else:
            self.cdr_skip(f2.type, ind, fpath + f2.name)

    def cdr_default(self, t: FieldType, default: Any, ind: int, fpath: str) -> None:
        dst = self.dst
        if not t.is_array:
            if t.is_string:
                if t.base == "wstring":
                    units = str(default or "").encode("utf-16-le")
                    dst.fixed(ind, "I", str(len(units) // 2))
                    data = b"".join(struct.pack("<I", u) for (u,) in
                                    struct.iter_unpack("<H", units))
                    dst.piece(ind, repr(data), str(len(data)))
                    dst.phase.advance(len(data))
                else:
                    data = str(default or "").encode() + b"\0"
                    dst.fixed(ind, "I", str(len(data)))
                    dst.piece(ind, repr(data), str(len(data)))
                    dst.phase.advance(len(data))
            elif t.is_primitive:
                value = default if default is not None else (0.0 if t.base.startswith("float")
                                                             else 0)
                dst.fixed(ind, STRUCT_CODE[t.base], repr(value))
            else:
                for f in self.mapper.ros2.message(t.base).fields:
                    self.cdr_default(f.type, f.default, ind, f"{fpath}.{f.name}")
            return
        items = list(default) if default is not None else []
        if t.kind == ARRAY and not items and not t.is_nested:
            zero: Any = "" if t.is_string else False if t.base == "bool" else \
                0.0 if t.base.startswith("float") else 0
            items = [zero] * t.size
        if t.is_sequence:
            dst.fixed(ind, "I", str(len(items)))
        if t.is_nested:
            for _ in range(t.size if t.kind == ARRAY else 0):
                self.cdr_default(t.element(), None, ind, fpath + "[]")
            return
        if t.is_string:
            for item in items:
                self.cdr_default(t.element(), item, ind, fpath + "[]")
            return
        if not items:
            return
        code = STRUCT_CODE[t.base]
        size = PRIMITIVE_SIZE[t.base]
        dst.align(ind, size)
        data = struct.pack(f"<{len(items)}{code}", *items)
        dst.piece(ind, repr(data), str(len(data)))
        dst.phase.advance(len(data))

    def cdr_skip(self, t: FieldType, ind: int, fpath: str) -> None:
        src = self.src
        if not t.is_array:
            if t.is_string:
                n = self.tmp("_n")
                src.fixed(ind, "I", n)
                nbytes = f"4 * {n}" if t.base == "wstring" else n
                src.need(ind, nbytes, fpath)
                src.skip(ind, nbytes)
                src.phase.forget(1)
            elif t.is_primitive:
                src.fixed(ind, copy_code(t.base), None)
            else:
                for f in self.mapper.ros2.message(t.base).fields:
                    self.cdr_skip(f.type, ind, f"{fpath}.{f.name}")
            return
        if t.kind == ARRAY:
            count = str(t.size)
        else:
            count = self.tmp("_n")
            src.fixed(ind, "I", count)
            src.flush(ind)
        if t.is_primitive and not t.is_string:
            size = PRIMITIVE_SIZE[t.base]
            if t.kind == ARRAY:
                src.align(ind, size)
            else:
                src.align_elements(ind, count, size)
            nbytes = f"{count} * {size}"
            src.need(ind, nbytes, fpath)
            src.skip(ind, nbytes)
            src.after(t, t.size * size if t.kind == ARRAY else None)
            return
        self.need_elements(ind, count, self.cdr_min(t.element()), fpath)
        src.flush(ind)
        self.emit(ind, f"for _ in range({count}):")
        src.unknown()
        self.cdr_skip(t.element(), ind + 1, fpath + "[]")
        src.flush(ind + 1)
        self.emit(ind + 1, "pass")
        src.unknown()


def flat_layout(nested: Any, gen: _Gen) -> Optional[Tuple[int, int]]:
    """(size, alignment) when a nested mapping's elements have the same bytes in ROS 1 and
    CDR once aligned: fixed-size primitives only, none dropped, defaulted or bool, no padding
    between them, the size a multiple of the alignment. None otherwise."""
    if nested is None:
        return None
    layout: List[int] = []

    def collect(m: Any) -> bool:
        if m.dropped or m.defaulted:
            return False
        for link in m.links:
            if link.ros1_path is None or len(link.ros1_path) != 1 or link.ros1_field is None:
                return False
            t = link.ros2.type
            if t.is_array:
                return False
            if link.nested is not None:
                if not collect(link.nested):
                    return False
            elif t.is_string or not t.is_primitive or t.base == "bool":
                return False
            else:
                layout.append(PRIMITIVE_SIZE[t.base])
        return True

    if not collect(nested) or not layout:
        return None
    align = max(layout)
    offset = 0
    for size in layout:
        if offset % size:
            return None
        offset += size
    if offset % align:
        return None
    return offset, align


def generate_source(mapping: Any) -> str:
    """The Python source of the two converters of ``mapping``."""
    structs: Dict[str, str] = {}
    to_cdr = _Gen(mapping, True, structs)
    to_cdr.message(mapping, 1, "", "0")
    to_cdr.flush(1)
    to_ros1 = _Gen(mapping, False, structs)
    to_ros1.message(mapping, 1, "", "seq")
    to_ros1.flush(1)
    r1, r2 = mapping.ros1_type, mapping.ros2_type
    body: List[str] = []
    if structs:
        body += ["", "# fixed-size runs: packed on the ROS 1 side, with CDR's padding ('x')"]
        body += [f"{n} = _Struct({'<' + fmt!r})"
                 for fmt, n in sorted(structs.items(), key=lambda kv: kv[1])]
    body += ["", "", "def ros1_to_cdr(v):",
             f'    """The CDR body of ROS 2 {r2} from ROS 1 {r1} bytes ``v`` (a memoryview)."""',
             "    out = [_HEADER]", "    p = pos = 0"]
    body += to_cdr.lines
    body += ["    if p != len(v):", f"        raise _leftover({r1!r}, len(v), p)",
             "    return out", "", "",
             "def cdr_to_ros1(v, seq=0):",
             f'    """ROS 1 {r1} bytes from the CDR body ``v`` of ROS 2 {r2} (a memoryview);',
             '    ``seq`` goes into the Header\'s seq (ROS 2 has none)."""',
             "    out = []", "    p = 0"]
    body += to_ros1.lines
    body += ["    if p > len(v):", f"        raise _leftover({r2!r}, len(v), p)",
             "    return out", ""]
    text = "\n".join(body)
    exports = {"_Struct": "Struct", "_ZEROS": "ZEROS", "_HEADER": "CDR_LE_HEADER",
               "_BOOL_TABLE": "BOOL_TABLE", "_short": "short", "_too_many": "too_many",
               "_too_long": "too_long", "_leftover": "leftover"}
    used = [alias for alias in exports if re.search(rf"\b{alias}\b", text)]
    head = [f"# ROS 1 {r1} <-> ROS 2 {r2} byte converters, generated by "
            f"minros.ros2.types.transcode.",
            "from minros.ros2.types.transcode import ("]
    head += [f"    {exports[a]} as {a}," for a in used]
    head.append(")")
    return "\n".join(head + body)


# -- what generated converters use -----------------------------------------------------------

Struct = struct.Struct
ZEROS = tuple(bytes(n) for n in range(8))
CDR_LE_HEADER = b"\x00\x01\x00\x00"


def short(kind: str, type_: str, field: str, need: int, have: int) -> DeserializationError:
    return DeserializationError(f"{type_}: field {field} needs {need} bytes but only {have} "
                                f"remain (truncated {kind} data or a bad length)")


def too_many(kind: str, type_: str, field: str, count: int, have: int) -> DeserializationError:
    return DeserializationError(f"{type_}: field {field} claims {count} elements but only "
                                f"{have} bytes of {kind} data remain")


def too_long(type_: str, field: str, count: int, bound: int) -> SerializationError:
    return SerializationError(f"{type_}: field {field} has {count} elements (or bytes); its ROS 2 "
                              f"type allows at most {bound}")


def leftover(type_: str, have: int, used: int) -> DeserializationError:
    if used > have:
        return DeserializationError(f"{type_}: the data ends {used - have} bytes early "
                                    f"(truncated, or not a {type_})")
    return DeserializationError(f"{type_}: {have - used} bytes left over after the message "
                                f"(not a {type_}?)")


class Transcoder:
    """ROS 1 bytes <-> CDR bytes for one mapped type pair (see the module docstring)."""

    def __init__(self, mapping: Any, source: str, namespace: Dict[str, Any]) -> None:
        self.mapping = mapping
        self.ros1_type: str = mapping.ros1_type
        self.ros2_type: str = mapping.ros2_type
        self.source = source
        #: whether the ROS 1 type has a top-level Header (whose seq :meth:`cdr_to_ros1` fills)
        self.has_header: bool = mapping.ros1.has_header
        self._to_cdr: Callable[[memoryview], List[Any]] = namespace["ros1_to_cdr"]
        self._to_ros1: Callable[..., List[Any]] = namespace["cdr_to_ros1"]

    def ros1_to_cdr(self, data: Any) -> bytes:
        """The CDR bytes (with the encapsulation header) of ROS 1 message bytes ``data``."""
        view = data if data.__class__ is memoryview else memoryview(data)
        try:
            return b"".join(self._to_cdr(view))
        except struct.error as exc:
            raise DeserializationError(f"{self.ros1_type}: truncated or invalid ROS 1 data: "
                                       f"{exc}") from None

    def cdr_to_ros1(self, data: Any, seq: int = 0) -> bytes:
        """ROS 1 message bytes from CDR bytes ``data`` (header included); ``seq`` is written
        into a top-level Header's seq."""
        view = data if data.__class__ is memoryview else memoryview(data)
        if len(view) < 4 or view[0] != 0 or view[1] != 1:
            raise DeserializationError(
                f"{self.ros2_type}: not little-endian plain CDR (encapsulation "
                f"{bytes(view[:2]).hex() or 'missing'}, expected 0001)")
        try:
            return b"".join(self._to_ros1(view[4:], seq))
        except struct.error as exc:
            raise DeserializationError(f"{self.ros2_type}: truncated or invalid CDR data: "
                                       f"{exc}") from None

    def __repr__(self) -> str:
        return f"<Transcoder ROS 1 {self.ros1_type} <-> ROS 2 {self.ros2_type}>"


def build_transcoder(mapping: Any) -> Transcoder:
    source = generate_source(mapping)
    filename = f"<minros ros2 transcode {mapping.ros1_type} {mapping.ros2_type}>"
    linecache.cache[filename] = (len(source), None, source.splitlines(True), filename)
    namespace: Dict[str, Any] = {"__name__": "minros.ros2.types.generated"}
    exec(compile(source, filename, "exec"), namespace)
    return Transcoder(mapping, source, namespace)
