"""genpy's code generator: the Python message modules ROS's genpy writes, line for line.

minros's own classes come from :mod:`minros.msgs.codegen` (struct runs, bounds checks,
``_deserialize_fresh``). This module exists for the code that expects genpy itself: catkin's
``genmsg_py.py``/``gensrv_py.py`` steps, tools that call ``genpy.generator`` and the unit
tests that compare its output with stored text. It follows genpy 0.6 (the version Debian
ships), with genpy's later fix to ``reduce_pattern`` (a run of ``9`` is a number, not a type).

genpy's API is a set of module functions sharing three pieces of state: the counter that
names temporaries (``_v1``, ``_v2``, ...), the stack of field prefixes (``self.``, ``_v1.``,
``val1.``) and the struct patterns the module being written needs. They live in one
:class:`Emission`; the module functions act on the default one, as genpy's do, so that a
package generated in one process numbers its temporaries as genpy numbers them.
"""

from __future__ import annotations

import errno
import itertools
import keyword
import os
import struct
import sys
import traceback
from typing import Any, Callable, Dict, Iterator, List, Optional, Sequence, Tuple

from minros.names import is_legal_resource_base_name

from . import loader
from .loader import (
    DURATION,
    HEADER,
    TIME,
    Constant,
    InvalidMsgSpec,
    MsgContext,
    MsgGenerationException,
    MsgSpec,
    SrvSpec,
    bare_msg_type,
    compute_full_type_name,
    parse_type,
)

INDENT = "  "

#: primitive type -> struct code; bool travels as an unsigned byte, char and byte as genpy
#: wrote them (char unsigned, byte signed)
SIMPLE_TYPES_DICT: Dict[str, str] = {
    "int8": "b", "uint8": "B", "bool": "B", "int16": "h", "uint16": "H", "int32": "i",
    "uint32": "I", "int64": "q", "uint64": "Q", "float32": "f", "float64": "d",
    "char": "B", "byte": "b",
}
SIMPLE_TYPES: List[str] = list(SIMPLE_TYPES_DICT)

#: numpy's name of each primitive's dtype, as generated numpy code spells it
NUMPY_DTYPE: Dict[str, str] = {
    "float32": "numpy.float32", "float64": "numpy.float64", "bool": "numpy.bool",
    "int8": "numpy.int8", "int16": "numpy.int16", "int32": "numpy.int32",
    "int64": "numpy.int64", "uint8": "numpy.uint8", "uint16": "numpy.uint16",
    "uint32": "numpy.uint32", "uint64": "numpy.uint64", "char": "numpy.uint8",
    "byte": "numpy.int8",
}

_INTEGER_TYPES = ("byte", "int8", "int16", "int32", "int64",
                  "char", "uint8", "uint16", "uint32", "uint64")
#: fixed arrays of these start as ``[default] * n``; others as n distinct instances
_REPEATABLE = ("byte", "int8", "int16", "int32", "int64", "uint16", "uint32", "uint64",
               "float32", "float64", "string", "bool")
_BYTES_LIKE = ("uint8", "char")  # arrays of these are bytes objects


def is_simple(type_: str) -> bool:
    """Whether ``type_`` has a fixed wire size: every primitive but string."""
    return type_ in SIMPLE_TYPES_DICT


# ---------------------------------------------------------------------------------------------
# the shared state

class Emission:
    """What the code being written so far needs: temporaries, field prefixes, patterns."""

    def __init__(self) -> None:
        self.counter = 0
        self.context = ""  # prefix of the fields being (de)serialized: 'self.', '_v1.', ''
        self.stack: List[str] = []
        self.patterns: List[str] = []

    def next_var(self) -> str:
        self.counter += 1
        return f"_v{self.counter}"

    def push(self, context: str) -> None:
        self.stack.append(self.context)
        self.context = context

    def pop(self) -> None:
        self.context = self.stack.pop()


_emission = Emission()


def next_var() -> str:
    """A new temporary's name: ``_v1``, ``_v2``, ..."""
    return _emission.next_var()


def reset_var() -> None:
    """Number temporaries from ``_v1`` again."""
    _emission.counter = 0


def push_context(context: str) -> None:
    """Fields are now read from ``context`` (``'self.'``, ``'_v3.'``, ...)."""
    _emission.push(context)


def pop_context() -> None:
    _emission.pop()


def add_pattern(pattern: str) -> None:
    """Record that the module needs a ``_get_struct_<pattern>()`` accessor."""
    _emission.patterns.append(pattern)


def get_patterns() -> List[str]:
    return list(_emission.patterns)


def clear_patterns() -> None:
    _emission.patterns = []


# ---------------------------------------------------------------------------------------------
# struct expressions (genpy.generate_struct) and numpy ones (genpy.generate_numpy)

def compute_struct_pattern(types: Optional[Sequence[str]]) -> Optional[str]:
    """The struct codes of a run of fixed-size fields; None if any is not one (or no types)."""
    if not types:
        return None
    codes = [SIMPLE_TYPES_DICT.get(t) for t in types]
    return None if None in codes else "".join(codes)  # type: ignore[arg-type]


def reduce_pattern(pattern: str) -> str:
    """``'hhhhi'`` -> ``'4hi'``: runs of one code become a count; digits (array lengths)
    and patterns holding a ``%`` format are left alone."""
    if not pattern or len(pattern) == 1 or "%" in pattern:
        return pattern
    out = []
    for code, run in itertools.groupby(pattern):
        n = len(list(run))
        out.append(f"{n}{code}" if n > 1 and not code.isdigit() else code * n)
    return "".join(out)


def serialize(expr: str) -> str:
    """The statement writing ``expr`` to the buffer."""
    return f"buff.write({expr})"


def int32_pack(var: str) -> str:
    return serialize(f"_struct_I.pack({var})")


def int32_unpack(var: str, buff: str) -> str:
    return f"({var},) = _struct_I.unpack({buff})"


def pack(pattern: str, vars_: str) -> str:
    """Packing ``vars_`` with a literal pattern, through the module's cached Struct."""
    pattern = reduce_pattern(pattern)
    add_pattern(pattern)
    return serialize(f"_get_struct_{pattern}().pack({vars_})")


def pack2(pattern: str, vars_: str) -> str:
    """Packing ``vars_`` with a pattern held in a variable (or computed by an expression)."""
    return serialize(f"struct.Struct({pattern}).pack({vars_})")


def unpack(var: str, pattern: str, buff: str) -> str:
    pattern = reduce_pattern(pattern)
    add_pattern(pattern)
    return f"{var} = _get_struct_{pattern}().unpack({buff})"


def unpack2(var: str, pattern: str, buff: str) -> str:
    return f"{var} = struct.unpack({pattern}, {buff})"


def unpack3(var: str, struct_var: str, buff: str) -> str:
    return f"{var} = {struct_var}.unpack({buff})"


def pack_numpy(var: str) -> str:
    return serialize(f"{var}.tostring()")


def unpack_numpy(var: str, count: object, dtype: str, buff: str) -> str:
    return f"{var} = numpy.frombuffer({buff}, dtype={dtype}, count={count})"


# ---------------------------------------------------------------------------------------------
# types: specials, constructors, defaults, imports

class Special:
    """A builtin that is a class in Python (time, duration, Header): how to make one, what to
    run on it after deserializing, and what to import."""

    def __init__(self, constructor: str, post_deserialize: Optional[str], import_str: str) -> None:
        self.constructor = constructor
        self.post_deserialize = post_deserialize
        self.import_str = import_str

    def get_post_deserialize(self, varname: str) -> Optional[str]:
        return self.post_deserialize % varname if self.post_deserialize else None


_SPECIAL_TYPES = {
    HEADER: Special("std_msgs.msg._Header.Header()", None, "import std_msgs.msg"),
    TIME: Special("genpy.Time()", "%s.canon()", "import genpy"),
    DURATION: Special("genpy.Duration()", "%s.canon()", "import genpy"),
}


def is_special(type_: str) -> bool:
    return type_ in _SPECIAL_TYPES


def get_special(type_: str) -> Optional[Special]:
    return _SPECIAL_TYPES.get(type_)


def get_registered_ex(msg_context: MsgContext, type_: str) -> MsgSpec:
    """The registered spec of ``type_``, or MsgGenerationException naming the likely cause."""
    try:
        return msg_context.get_registered(type_)
    except Exception:
        raise MsgGenerationException(
            f"Unknown type [{type_}]. Please check that the manifest.xml correctly declares "
            "dependencies.") from None


def compute_pkg_type(package: str, type_: str) -> Tuple[str, str]:
    """``('pkg', 'Type')`` of ``type_``, an unqualified name taken to be in ``package``."""
    parts = type_.split("/")
    if len(parts) == 1:
        return package, parts[0]
    if len(parts) == 2:
        return parts[0], parts[1]
    raise MsgGenerationException(f"illegal message type: {type_}")


def compute_constructor(msg_context: MsgContext, package: str, type_: str) -> Optional[str]:
    """The expression making a new ``type_`` (None for arrays and unregistered types)."""
    special = get_special(type_)
    if special is not None:
        return special.constructor
    if bare_msg_type(type_) != type_:
        return None
    pkg, base = compute_pkg_type(package, type_)
    if not msg_context.is_registered(f"{pkg}/{base}"):
        return None
    return f"{pkg}.msg.{base}()"


def compute_post_deserialize(type_: str, varname: str) -> Optional[str]:
    special = get_special(type_)
    return special.get_post_deserialize(varname) if special is not None else None


def default_value(msg_context: MsgContext, field_type: str, default_package: str) -> Optional[str]:
    """The expression a field starts as (None for an unknown message type)."""
    if field_type in _INTEGER_TYPES:
        return "0"
    if field_type in ("float32", "float64"):
        return "0."
    if field_type == "string":
        return "''"
    if field_type == "bool":
        return "False"
    if not field_type.endswith("]"):
        return compute_constructor(msg_context, default_package, field_type)
    base, _, length = parse_type(field_type)
    if base in _BYTES_LIKE:
        return "b''" if length is None else rf"b'\0'*{length}"
    if length is None:
        return "[]"
    item = default_value(msg_context, base, default_package)
    if base in _REPEATABLE:
        return f"[{item}] * {length}"
    return f"[{item} for _ in range({length})]"


def compute_import(msg_context: MsgContext, package: str, type_: str) -> List[str]:
    """The import statements code using ``type_`` (from ``package``) needs, embedded types'
    included, without repeats."""
    orig_base = bare_msg_type(type_)
    pkg, base = compute_pkg_type(package, orig_base)
    full = f"{pkg}/{base}"
    # builtins are never qualified, so test the unresolved name; Header has two names
    if loader.is_builtin(orig_base) or loader.is_header_type(orig_base):
        special = get_special(base)
        return [special.import_str] if special is not None else []
    if not msg_context.is_registered(full):
        return []
    imports = [f"import {pkg}.msg"]
    for sub_type in get_registered_ex(msg_context, full).types:
        assert sub_type != full, f"msg [{full}] has circular self-dependencies"
        imports.extend(i for i in compute_import(msg_context, package, sub_type)
                       if i not in imports)
    return imports


def compute_full_text_escaped(msg_context: MsgContext, spec: MsgSpec) -> str:
    """The full definition text, safe inside a triple-quoted string."""
    return loader.compute_full_text(msg_context, spec).replace('"""', r'\"\"\"')


# ---------------------------------------------------------------------------------------------
# specs reshaped for code: flattened, Python-safe

def flatten(msg_context: MsgContext, msg: MsgSpec) -> MsgSpec:
    """A spec whose embedded (non-array) messages are replaced by their fields, named
    ``outer.inner``: serializer code reaches them directly. Not a legal spec otherwise."""
    types: List[str] = []
    names: List[str] = []
    for type_, name in zip(msg.types, msg.names):
        _, is_array, _ = parse_type(type_)
        if not is_array and msg_context.is_registered(type_):
            inner = flatten(msg_context, msg_context.get_registered(type_))
            types.extend(inner.types)
            names.extend(f"{name}.{sub}" for sub in inner.names)
        else:
            types.append(type_)
            names.append(name)
    return MsgSpec(types, names, msg.constants, msg.text, msg.full_name)


def _remap_reserved(field_name: str) -> str:
    """``'if'`` -> ``'if_'`` (also ``self``, the methods' instance); in a dotted name, the last part."""
    prefix, dot, last = field_name.rpartition(".")
    if not prefix:  # no dot, or a leading one: the whole name is the field
        prefix, dot, last = "", "", field_name
    if keyword.iskeyword(last) or last == "self":
        last += "_"
    return prefix + dot + last


def make_python_safe(spec: MsgSpec) -> MsgSpec:
    """The spec with field and constant names that are Python keywords suffixed by ``_``."""
    constants = [Constant(c.type, _remap_reserved(c.name), c.val, c.val_text)
                 for c in spec.constants]
    return MsgSpec(spec.types, [_remap_reserved(n) for n in spec.names], constants, spec.text,
                   spec.full_name)


# ---------------------------------------------------------------------------------------------
# serializer bodies: generators of unindented lines

def len_serializer_generator(var: str, is_string: bool, serialize: bool) -> Iterator[str]:
    """The uint32 length before a string or array (for a string, only its computation: the
    length is packed with the bytes)."""
    if serialize:
        yield f"length = len({var})"
        if not is_string:
            yield int32_pack("length")
    else:
        yield "start = end"
        yield "end += 4"
        yield int32_unpack("length", "str[start:end]")


def string_serializer_generator(package: str, type_: str, name: str,
                                serialize: bool) -> Iterator[str]:
    """A string, or an array of uint8/char (bytes; a fixed-length one has no length prefix)."""
    if _emission.context and serialize:
        # the field is read twice: once into a local
        yield f"_x = {_emission.context}{name}"
        var = "_x"
    else:
        var = _emission.context + name
    base, _, length = parse_type(type_)
    is_bytes = base in _BYTES_LIKE
    if not is_bytes or length is None:
        yield from len_serializer_generator(var, True, serialize)
    if serialize:
        if is_bytes:
            yield "# - if encoded as a list instead, serialize as bytes instead of string"
            yield f"if type({var}) in [list, tuple]:"
            if length is None:
                yield INDENT + pack2("'<I%sB'%length", f"length, *{var}")
                yield "else:"
                yield INDENT + pack2("'<I%ss'%length", f"length, {var}")
            else:
                yield INDENT + pack(f"{length}B", f"*{var}")
                yield "else:"
                yield INDENT + pack(f"{length}s", var)
        else:
            yield f"if python3 or type({var}) == unicode:"
            yield INDENT + f"{var} = {var}.encode('utf-8')"
            yield INDENT + f"length = len({var})"
            yield pack2("'<I%ss'%length", f"length, {var}")
        return
    yield "start = end"
    if length is not None:
        yield f"end += {length}"
        yield f"{var} = str[start:end]"
    elif is_bytes:
        yield "end += length"
        yield f"{var} = str[start:end]"
    else:
        yield "end += length"
        yield "if python3:"
        yield INDENT + f"{var} = str[start:end].decode('utf-8', 'rosmsg')"
        yield "else:"
        yield INDENT + f"{var} = str[start:end]"


def _simple_array(base: str, var: str, length: Optional[int], serialize: bool,
                  is_numpy: bool) -> Iterator[str]:
    code = SIMPLE_TYPES_DICT[base]
    if length is None:
        yield f"pattern = '<%s{code}'%length"
        if serialize:
            yield pack_numpy(var) if is_numpy else pack2("pattern", "*" + var)
        else:
            yield "start = end"
            yield "s = struct.Struct(pattern)"
            yield "end += s.size"
            yield (unpack_numpy(var, "length", NUMPY_DTYPE[base], "str[start:end]") if is_numpy
                   else unpack3(var, "s", "str[start:end]"))
    else:
        pattern = f"{length}{code}"
        if serialize:
            yield pack_numpy(var) if is_numpy else pack(pattern, "*" + var)
        else:
            yield "start = end"
            yield f"end += {struct.calcsize('<' + pattern)}"
            yield (unpack_numpy(var, length, NUMPY_DTYPE[base], "str[start:end]") if is_numpy
                   else unpack(var, pattern, "str[start:end]"))
    if not serialize and base == "bool":
        yield f"{var} = list(map(bool, {var}))"


def array_serializer_generator(msg_context: MsgContext, package: str, type_: str, name: str,
                               serialize: bool, is_numpy: bool) -> Iterator[str]:
    """An array field: bytes for uint8/char, one struct call for other primitives, else a
    loop over the items (strings or messages)."""
    base, is_array, length = parse_type(type_)
    if not is_array:
        raise MsgGenerationException(f"Invalid array spec: {type_}")
    if base in _BYTES_LIKE:
        yield from string_serializer_generator(package, type_, name, serialize)
        return
    var = _emission.context + name
    if length is None:
        yield from len_serializer_generator(var, False, serialize)
    if is_simple(base):
        yield from _simple_array(base, var, length, serialize, is_numpy)
        return
    loop_var = f"val{len(_emission.stack)}"
    if base == "string":
        push_context("")
        items = string_serializer_generator(package, base, loop_var, serialize)
    else:
        push_context(f"{loop_var}.")
        items = serializer_generator(
            msg_context, make_python_safe(get_registered_ex(msg_context, base)), serialize, is_numpy)
    if serialize:
        if length is not None:
            yield f"if len({var}) != {length}:"
            yield (INDENT + "self._check_types(ValueError(\"Expecting %s items but found %s "
                   f"when writing '%s'\" % ({length}, len({var}), '{var}')))")
        yield f"for {loop_var} in {var}:"
    else:
        yield f"{var} = []"
        yield f"for i in range(0, {'length' if length is None else length}):"
        if base != "string":
            yield INDENT + f"{loop_var} = {compute_constructor(msg_context, package, base)}"
    for line in items:
        yield INDENT + line
    if not serialize:
        yield INDENT + f"{var}.append({loop_var})"
    pop_context()


def complex_serializer_generator(msg_context: MsgContext, package: str, type_: str, name: str,
                                 serialize: bool, is_numpy: bool) -> Iterator[str]:
    """A field that is not a run of primitives: an array, a string, or an embedded message
    (through a temporary, ``_v<n>``)."""
    _, is_array, _ = parse_type(type_)
    if is_array:
        yield from array_serializer_generator(msg_context, package, type_, name, serialize,
                                              is_numpy)
        return
    if type_ == "string":
        yield from string_serializer_generator(package, type_, name, serialize)
        return
    if not is_special(type_):
        type_ = "/".join(compute_pkg_type(package, type_))
    if not msg_context.is_registered(type_):
        raise MsgGenerationException(f"Unknown type: {type_}. Package context is {package}")
    var = next_var()
    yield f"{var} = {_emission.context}{name}"
    push_context(var + ".")
    yield from serializer_generator(
        msg_context, make_python_safe(get_registered_ex(msg_context, type_)), serialize, is_numpy)
    pop_context()


def simple_serializer_generator(msg_context: MsgContext, spec: MsgSpec, start: int, end: int,
                                serialize: bool) -> Iterator[str]:
    """Fields ``start:end`` of ``spec``, all fixed-size, in one struct call."""
    context = _emission.context
    names = spec.names[start:end]
    if end - start > 1 and context.endswith("."):
        yield "_x = " + context[:-1]
        vars_ = "_x." + ", _x.".join(names)
    elif serialize and end - start == 1 and context.endswith("."):
        yield f"_x = {context}{names[0]}"
        vars_ = "_x"
    else:
        vars_ = context + (", " + context).join(names)
    pattern = compute_struct_pattern(spec.types[start:end]) or ""
    if serialize:
        yield pack(pattern, vars_)
        return
    yield "start = end"
    yield f"end += {struct.calcsize('<' + reduce_pattern(pattern))}"
    yield unpack(f"({vars_},)", pattern, "str[start:end]")
    for name, type_ in zip(names, spec.types[start:end]):
        if type_ == "bool":  # read as a byte: make it a bool again
            yield f"{context}{name} = bool({context}{name})"


_MAX_CHUNK = 255  # fields per struct call


def serializer_generator(msg_context: MsgContext, spec: Optional[MsgSpec], serialize: bool,
                         is_numpy: bool) -> Iterator[str]:
    """The (de)serialization of every field of ``spec``: runs of fixed-size fields in chunks
    of at most 255, other fields one by one."""
    if spec is None:
        raise MsgGenerationException("spec is none")
    if serialize and not spec.names:
        yield "pass"
        return

    def run(first: int, stop: int) -> Iterator[str]:
        for chunk in range(first, stop, _MAX_CHUNK):
            yield from simple_serializer_generator(msg_context, spec, chunk,
                                                   min(chunk + _MAX_CHUNK, stop), serialize)

    first = 0
    for i, type_ in enumerate(spec.types):
        if is_simple(type_):
            continue
        yield from run(first, i)
        first = i + 1
        yield from complex_serializer_generator(msg_context, spec.package, type_, spec.names[i],
                                                serialize, is_numpy)
    yield from run(first, len(spec.types))


_SERIALIZE_ERRORS = (
    "except struct.error as se: self._check_types(struct.error(\"%s: '%s' when writing '%s'\" "
    "% (type(se), str(se), str(locals().get('_x', self)))))",
    "except TypeError as te: self._check_types(ValueError(\"%s: '%s' when writing '%s'\" "
    "% (type(te), str(te), str(locals().get('_x', self)))))",
)


def serialize_fn_generator(msg_context: MsgContext, spec: MsgSpec,
                           is_numpy: bool = False) -> Iterator[str]:
    """The body of ``serialize`` (or ``serialize_numpy``)."""
    yield "try:"
    push_context("self.")
    for line in serializer_generator(msg_context, make_python_safe(flatten(msg_context, spec)),
                                     True, is_numpy):
        yield "  " + line
    pop_context()
    yield from _SERIALIZE_ERRORS


def deserialize_fn_generator(msg_context: MsgContext, spec: MsgSpec,
                             is_numpy: bool = False) -> Iterator[str]:
    """The body of ``deserialize`` (or ``deserialize_numpy``)."""
    yield "if python3:"
    yield INDENT + 'codecs.lookup_error("rosmsg").msg_type = self._type'
    yield "try:"
    for type_, name in spec.fields():
        if msg_context.is_registered(type_):
            yield f"  if self.{name} is None:"
            yield f"    self.{name} = {compute_constructor(msg_context, spec.package, type_)}"
    yield "  end = 0"
    push_context("self.")
    for line in serializer_generator(msg_context, make_python_safe(flatten(msg_context, spec)),
                                     False, is_numpy):
        yield "  " + line
    pop_context()
    for type_, name in spec.fields():
        code = compute_post_deserialize(type_, f"self.{name}")
        if code:
            yield "  " + code
    yield "  return self"
    yield "except struct.error as e:"
    yield "  raise genpy.DeserializationError(e)  # most likely buffer underfill"


# ---------------------------------------------------------------------------------------------
# whole modules

def _constant_line(c: Constant) -> str:
    if c.type != "string":
        return f"  {c.name} = {c.val}"
    val = str(c.val)
    if '"' in val and "'" in val:
        escaped = val.replace("\\", "\\\\").replace('"', '\\"')
        return f'  {c.name} = "{escaped}"'
    if '"' in val:
        return f"  {c.name} = r'{val}'"
    if "'" in val:
        return f'  {c.name} = r"{val}"'
    return f"  {c.name} = '{val}'"


_INIT_DOC = '''
  def __init__(self, *args, **kwds):
    """
    Constructor. Any message fields that are implicitly/explicitly
    set to None will be assigned a default value. The recommend
    use is keyword arguments as this is more robust to future message
    changes.  You cannot mix in-order arguments and keyword arguments.

    The available fields are:
       {names}

    :param args: complete set of field values, in .msg order
    :param kwds: use keyword arguments corresponding to message field names
    to set specific fields.
    """
    if args or kwds:
      super({cls}, self).__init__(*args, **kwds)'''

_METHOD_DOCS = {
    "serialize": '''
  def _get_types(self):
    """
    internal API method
    """
    return self._slot_types

  def serialize(self, buff):
    """
    serialize message into buffer
    :param buff: buffer, ``StringIO``
    """''',
    "deserialize": '''
  def deserialize(self, str):
    """
    unpack serialized message in str into this message instance
    :param str: byte array of serialized message, ``str``
    """''',
    "serialize_numpy": '''
  def serialize_numpy(self, buff, numpy):
    """
    serialize message with numpy array types into buffer
    :param buff: buffer, ``StringIO``
    :param numpy: numpy python module
    """''',
    "deserialize_numpy": '''
  def deserialize_numpy(self, str, numpy):
    """
    unpack serialized message in str into this message instance using numpy for array types
    :param str: byte array of serialized message, ``str``
    :param numpy: numpy python module
    """''',
}


def msg_generator(msg_context: MsgContext, spec: MsgSpec,
                  search_path: Dict[str, List[str]]) -> Iterator[str]:
    """The lines of the module genpy writes for message ``spec``."""
    try:
        loader.load_depends(msg_context, spec, search_path)
    except InvalidMsgSpec as exc:
        raise MsgGenerationException(
            f"Cannot generate .msg for {spec.package}/{spec.short_name}: {exc}") from None
    md5sum = loader.compute_md5(msg_context, spec)  # before renaming fields
    safe = make_python_safe(spec)
    names = safe.names
    clear_patterns()

    yield "# This Python file uses the following encoding: utf-8"
    yield f'"""autogenerated by genpy from {safe.full_name}.msg. Do not edit."""'
    yield "import codecs"
    yield "import sys"
    yield "python3 = True if sys.hexversion > 0x03000000 else False"
    yield "import genpy\nimport struct\n"
    imports = sorted({i for t in safe.types for i in compute_import(msg_context, safe.package, t)})
    yield from (i for i in imports if i)
    yield ""

    yield f"class {safe.short_name}(genpy.Message):"
    yield f'  _md5sum = "{md5sum}"'
    yield f'  _type = "{safe.full_name}"'
    yield f"  _has_header = {safe.has_header()}  # flag to mark the presence of a Header object"
    full_text = compute_full_text_escaped(msg_context, safe)
    if full_text.endswith('"') and not full_text.endswith('\\"'):
        full_text = full_text[:-1] + '\\"'
    yield f'  _full_text = """{full_text}"""'
    if safe.constants:
        yield "  # Pseudo-constants"
        yield from (_constant_line(c) for c in safe.constants)
        yield ""
    if names:
        yield "  __slots__ = ['" + "','".join(names) + "']"
        yield "  _slot_types = ['" + "','".join(safe.types) + "']"
    else:
        yield "  __slots__ = []"
        yield "  _slot_types = []"

    yield _INIT_DOC.format(names=",".join(names), cls=safe.short_name)
    if names:
        yield "      # message fields cannot be None, assign default values for those that are"
        for type_, name in zip(safe.types, names):
            yield f"      if self.{name} is None:"
            yield f"        self.{name} = {default_value(msg_context, type_, safe.package)}"
        yield "    else:"
        for type_, name in zip(safe.types, names):
            yield f"      self.{name} = {default_value(msg_context, type_, safe.package)}"

    for method, body in (("serialize", serialize_fn_generator(msg_context, safe)),
                         ("deserialize", deserialize_fn_generator(msg_context, safe)),
                         ("serialize_numpy", serialize_fn_generator(msg_context, safe, True)),
                         ("deserialize_numpy", deserialize_fn_generator(msg_context, safe, True))):
        yield _METHOD_DOCS[method]
        for line in body:
            yield "    " + line
        if method.startswith("deserialize"):
            yield ""

    yield "_struct_I = genpy.struct_I"
    yield "def _get_struct_I():"
    yield "    global _struct_I"
    yield "    return _struct_I"
    for pattern in sorted(set(get_patterns())):
        if pattern == "I":  # genpy.struct_I, above
            continue
        var = "_struct_" + pattern.replace("<", "")
        yield f"{var} = None"
        yield f"def _get{var}():"
        yield f"    global {var}"
        yield f"    if {var} is None:"
        yield f'        {var} = struct.Struct("<{pattern}")'
        yield f"    return {var}"
    clear_patterns()


def srv_generator(msg_context: MsgContext, spec: SrvSpec,
                  search_path: Dict[str, List[str]]) -> Iterator[str]:
    """The module genpy writes for a service: both message classes, then the service's."""
    for half in (spec.request, spec.response):
        yield from msg_generator(msg_context, half, search_path)
    loader.load_depends(msg_context, spec, search_path)
    md5 = loader.compute_md5(msg_context, spec)
    yield f"class {spec.short_name}(object):"
    yield f"  _type          = '{spec.full_name}'"
    yield f"  _md5sum = '{md5}'"
    yield f"  _request_class  = {spec.short_name}Request"
    yield f"  _response_class = {spec.short_name}Response"


def _module_name(type_name: str) -> str:
    """``'String'`` -> ``'_String'``: the module never collides with the class it holds."""
    return "_" + type_name


def compute_resource_name(filename: str, ext: str) -> str:
    return os.path.basename(filename)[:-len(ext)]


def compute_outfile_name(outdir: str, infile_name: str, ext: str) -> str:
    return os.path.join(outdir, _module_name(compute_resource_name(infile_name, ext)) + ".py")


class Generator:
    """Writes one module per definition file of a package (genpy's MsgGenerator/SrvGenerator)."""

    def __init__(self, what: str, ext: str, spec_loader_fn: Callable[..., Any],
                 generator_fn: Callable[..., Any]) -> None:
        self.what = what
        self.ext = ext
        self.spec_loader_fn = spec_loader_fn
        self.generator_fn = generator_fn

    def generate(self, msg_context: MsgContext, full_type: str, f: str, outdir: str,
                 search_path: Dict[str, List[str]]) -> str:
        try:
            os.makedirs(outdir)
        except OSError as exc:  # another generator made it first
            if exc.errno != errno.EEXIST:
                raise
        spec = self.spec_loader_fn(msg_context, f, full_type)
        outfile = compute_outfile_name(outdir, os.path.basename(f), self.ext)
        with open(outfile, "w") as out:
            for line in self.generator_fn(msg_context, spec, search_path):
                out.write(line + "\n")
        return outfile

    def generate_messages(self, package: str, package_files: Sequence[str], outdir: str,
                          search_path: Dict[str, List[str]]) -> int:
        """Generate every file; 1 if any failed (each failure printed), else 0."""
        if not is_legal_resource_base_name(package):
            raise MsgGenerationException(
                f"\nERROR: package name '{package}' is illegal and cannot be used in message "
                "generation.\nPlease see http://ros.org/wiki/Names")
        msg_context = MsgContext.create_default()
        retcode = 0
        for f in package_files:
            try:
                f = os.path.abspath(f)
                full_type = compute_full_type_name(package, os.path.basename(f))
                self.generate(msg_context, full_type, f, outdir, search_path)
            except Exception as exc:
                if not isinstance(exc, (MsgGenerationException, InvalidMsgSpec)):
                    traceback.print_exc()
                print(f"\nERROR: Unable to generate {self.what} for package '{package}': while "
                      f"processing '{f}': {exc}\n", file=sys.stderr)
                retcode = 1
        return retcode


class MsgGenerator(Generator):
    """Generates the modules of a package's ``.msg`` files."""

    def __init__(self) -> None:
        super().__init__("messages", loader.EXT_MSG, loader.load_msg_from_file, msg_generator)


class SrvGenerator(Generator):
    """Generates the modules of a package's ``.srv`` files."""

    def __init__(self) -> None:
        super().__init__("services", loader.EXT_SRV, loader.load_srv_from_file, srv_generator)


# ---------------------------------------------------------------------------------------------
# the package's msg/__init__.py (genpy.generate_initpy)

def write_module(basedir: str, generated_modules: Sequence[str]) -> None:
    """``basedir/__init__.py`` importing everything of each generated module."""
    if not os.path.exists(basedir):
        os.makedirs(basedir)
    elif not os.path.isdir(basedir):
        raise MsgGenerationException(
            f"file preventing the creating of module directory: {basedir}")
    with open(os.path.join(basedir, "__init__.py"), "w") as f:
        for module in generated_modules:
            f.write(f"from .{module} import *\n")


def write_modules(outdir: str) -> int:
    """The ``__init__.py`` of a folder of generated modules (``_Name.py``), sorted by type."""
    if not os.path.isdir(outdir):
        return 0
    types = {name[1:-3] for name in os.listdir(outdir)
             if name.endswith(".py") and name != "__init__.py"}
    write_module(outdir, [_module_name(t) for t in sorted(types)])
    return 0


# ---------------------------------------------------------------------------------------------
# the command line of genmsg_py.py / gensrv_py.py (genpy.genpy_main)

def usage(progname: str) -> None:
    print(f"{progname} file(s)")


def genmain(argv: Sequence[str], progname: str, gen: Generator) -> None:
    """``PROG [--initpy] -p PKG -o OUTDIR -I pkg:dir ... FILE...``; exits with genpy's codes:
    1 for a bad definition, 2 for a generation error, 3 for anything else."""
    import argparse

    parser = argparse.ArgumentParser(prog=progname, usage=f"{progname} file")
    parser.add_argument("--initpy", action="store_true", default=False)
    parser.add_argument("-p", dest="package")
    parser.add_argument("-o", dest="outdir")
    parser.add_argument("-I", dest="includepath", action="append")
    parser.add_argument("files", nargs="*")
    options = parser.parse_args(list(argv)[1:])
    retcode = 0
    try:
        if options.initpy:
            if not options.outdir:
                parser.error("Missing args")
            retcode = write_modules(options.outdir)
        else:
            if not options.files:
                parser.error("please specify args")
            os.makedirs(options.outdir, exist_ok=True)
            search_path = loader.includepath_to_dict(options.includepath)
            retcode = gen.generate_messages(options.package, options.files, options.outdir,
                                            search_path)
    except InvalidMsgSpec as exc:
        print("ERROR: ", exc, file=sys.stderr)
        retcode = 1
    except MsgGenerationException as exc:
        print("ERROR: ", exc, file=sys.stderr)
        retcode = 2
    except Exception as exc:
        traceback.print_exc()
        print("ERROR: ", exc)
        retcode = 3
    sys.exit(retcode or 0)
