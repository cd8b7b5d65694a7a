"""Test helpers for ROS 2 types: hypothesis strategies, plain values, the rclpy and rosidl oracles.

Plain values (:func:`plain`) are what both sides of a comparison reduce to: dicts of members,
lists for every array (bytes as lists of ints), ints, floats, bools, strings. The oracles are
scripts run by the pip ROS 2's interpreters (``/opt/minros-ros2/<distro>/bin/python``, built
by scripts/install-ros2-reference.sh), one process per batch so a test run stays short:

* :func:`rclpy_check` decodes CDR bytes with rclpy's ``deserialize_message``, returns the plain
  value and rclpy's own ``serialize_message`` bytes of it, and the bytes and plain value of
  every type's default message;
* :func:`rosidl_hashes` runs rosidl (rosidl_adapter's .msg -> .idl and
  rosidl_generator_type_description) on definition files and returns its type descriptions.
"""

from __future__ import annotations

import json
import os
import subprocess
import tempfile
from pathlib import Path
from typing import Any, Dict, Iterable, List, Mapping, Optional, Sequence, Tuple

from .cdr import python_name
from .model import INT_RANGES, FieldType
from .registry import TypeRegistry

ROS2_HOME = Path(os.environ.get("MINROS_ROS2_HOME", "/opt/minros-ros2"))


def oracle_python(distro: str) -> Path:
    """The interpreter of the pip ROS 2 of ``distro``."""
    return ROS2_HOME / distro / "bin" / "python"


def oracle_available(distro: str) -> bool:
    return oracle_python(distro).exists()


# -- plain values ------------------------------------------------------------------------------

def plain(registry: TypeRegistry, name: str, obj: Any) -> Any:
    """The plain value of ``obj``, an instance of struct ``name`` (ours, or anything with the
    same attributes)."""
    struct = registry.message(name)
    out: Dict[str, Any] = {}
    if struct.is_empty:  # rosidl's placeholder member is not part of the value
        return out
    for f in struct.fields:
        out[f.name] = _plain_field(registry, f.type, getattr(obj, python_name(f.name)))
    return out


def _plain_field(registry: TypeRegistry, t: FieldType, value: Any) -> Any:
    if t.is_array:
        if t.base in ("uint8", "byte", "char"):
            if isinstance(value, (list, tuple)) and value and isinstance(value[0], bytes):
                return [b[0] for b in value]
            return list(bytes(value)) if isinstance(value, (bytes, bytearray, memoryview)) \
                else [int(x) for x in value]
        element = t.element()
        return [_plain_field(registry, element, item) for item in value]
    if t.is_nested:
        return plain(registry, t.base, value)
    if t.base == "byte" and isinstance(value, bytes):
        return value[0]
    if t.base == "bool":
        return bool(value)
    if t.base in ("float32", "float64"):
        return float(value)
    if t.is_string:
        return value if isinstance(value, str) else bytes(value).decode()
    return int(value)


# -- hypothesis strategies ------------------------------------------------------------------------

def strategy_for(registry: TypeRegistry, name: str, max_array: int = 3) -> Any:
    """A hypothesis strategy of instances of struct ``name``'s class."""
    from hypothesis import strategies as st

    cache: Dict[str, Any] = {}
    surrogates: Any = ("Cs",)  # not UTF-8 encodable
    text_chars = st.characters(blacklist_categories=surrogates, blacklist_characters="\x00")
    ascii_chars = st.characters(min_codepoint=1, max_codepoint=126)
    bmp_chars = st.characters(blacklist_categories=surrogates, blacklist_characters="\x00",
                              max_codepoint=0xFFFF)

    def scalar(t: FieldType) -> Any:
        if t.base in INT_RANGES:
            low, high = INT_RANGES[t.base]
            return st.integers(low, high)
        if t.base == "bool":
            return st.booleans()
        if t.base == "float32":
            return st.floats(allow_nan=False, width=32)
        if t.base == "float64":
            return st.floats(allow_nan=False)
        if t.base == "string":
            if t.string_bound:
                return st.text(ascii_chars, max_size=min(t.string_bound, 12))
            return st.text(text_chars, max_size=12)
        if t.base == "wstring":
            return st.text(bmp_chars, max_size=min(t.string_bound or 12, 12))
        return message(t.base)

    def field_strategy(t: FieldType) -> Any:
        if not t.is_array:
            return scalar(t)
        low = t.size if t.kind == "array" else 0
        high = t.size if t.kind == "array" else min(t.size, max_array) if t.size else max_array
        if t.base in ("uint8", "byte", "char"):
            return st.binary(min_size=low, max_size=high)
        items = st.lists(scalar(t.element()), min_size=low, max_size=high)
        if t.base in ("float32", "float64") or t.base in INT_RANGES:
            from array import array

            from .model import STRUCT_CODE

            code = STRUCT_CODE[t.base]
            def to_array(xs: List[Any], c: str = code) -> Any:
                return array(c, xs)

            return items.map(to_array)
        return items

    def message(type_name: str) -> Any:
        if type_name not in cache:
            codec = registry.codec(type_name)
            fields = {python_name(f.name): field_strategy(f.type)
                      for f in registry.message(type_name).fields}
            cache[type_name] = st.builds(codec.cls, **fields)
        return cache[type_name]

    return message(name)


def samples(strategy: Any, count: int, seed: int = 0) -> List[Any]:
    """``count`` examples of ``strategy``, drawn by a hypothesis run of its own (reproducible)."""
    from hypothesis import HealthCheck, given, settings
    from hypothesis import seed as hseed

    out: List[Any] = []

    @hseed(seed)
    @settings(max_examples=count, database=None, deadline=None,
              suppress_health_check=list(HealthCheck))
    @given(strategy)
    def collect(value: Any) -> None:
        out.append(value)

    collect()
    return out[-count:] if len(out) > count else out


# -- the rclpy oracle ---------------------------------------------------------------------------

RCLPY_ORACLE = r'''
import importlib, json, sys
from rclpy.serialization import deserialize_message, serialize_message

def message_class(name):
    pkg, ns, short = name.split("/")
    module = importlib.import_module(f"{pkg}.{ns}")
    for suffix in ("_Request", "_Response", "_Event"):
        if ns == "srv" and short.endswith(suffix):
            return getattr(getattr(module, short[:-len(suffix)]), suffix[1:])
    return getattr(module, short)

def plain(value, type_text=""):
    if hasattr(value, "get_fields_and_field_types"):
        return {f: plain(getattr(value, f), t)
                for f, t in value.get_fields_and_field_types().items()}
    if isinstance(value, bytes):
        return value[0] if type_text == "octet" else list(value)
    if hasattr(value, "tolist"):
        return value.tolist()
    if isinstance(value, (list, tuple)) or type(value).__name__ == "array":
        inner = type_text[len("sequence<"):].split(",")[0].rstrip(">") \
            if type_text.startswith("sequence<") else type_text.split("[")[0]
        return [plain(v, inner) for v in value]
    return value

out = []
for request in json.load(sys.stdin):
    name = request["type"]
    try:
        cls = message_class(name)
        if request.get("hex") is None:
            msg = cls()
        else:
            msg = deserialize_message(bytes.fromhex(request["hex"]), cls)
        out.append({"plain": plain(msg), "hex": serialize_message(msg).hex()})
    except Exception as exc:
        out.append({"error": f"{type(exc).__name__}: {exc}"})
json.dump(out, sys.stdout)
'''


def rclpy_check(distro: str, requests: Sequence[Tuple[str, Optional[bytes]]],
                timeout: float = 300.0) -> List[Dict[str, Any]]:
    """For each ``(type, cdr bytes or None)``: rclpy's plain value of the decoded message (or
    of the default message for None) and rclpy's ``serialize_message`` hex of it. One process."""
    payload = json.dumps([{"type": t, "hex": None if b is None else b.hex()}
                          for t, b in requests])
    env = {k: v for k, v in os.environ.items() if not k.startswith(("ROS_", "AMENT_", "RMW_"))}
    run = subprocess.run([str(oracle_python(distro)), "-c", RCLPY_ORACLE], input=payload,
                         capture_output=True, text=True, timeout=timeout, env=env)
    if run.returncode != 0:
        raise RuntimeError(f"the rclpy oracle ({distro}) failed: {run.stderr[-2000:]}")
    result: List[Dict[str, Any]] = json.loads(run.stdout)
    return result


# -- the rosidl oracle ---------------------------------------------------------------------------

ROSIDL_ORACLE = r'''
import json, pathlib, sys, io, contextlib
from rosidl_adapter.msg import convert_msg_to_idl
from rosidl_adapter.srv import convert_srv_to_idl
from rosidl_adapter.action import convert_action_to_idl
import rosidl_generator_type_description as g

request = json.load(sys.stdin)
root = pathlib.Path(request["root"])
includes = list(request["includes"])
result = {}
for package in request["packages"]:
    pkg_dir = root / "src" / package
    out_dir = root / "build" / package
    tuples = []
    with contextlib.redirect_stdout(io.StringIO()):
        for path in sorted(pkg_dir.glob("*/*")):
            kind = path.parent.name
            convert = {"msg": convert_msg_to_idl, "srv": convert_srv_to_idl,
                       "action": convert_action_to_idl}[kind]
            idl = convert(pkg_dir, package, path.relative_to(pkg_dir), out_dir / "idl" / kind)
            tuples.append(f"{out_dir / 'idl'}:{kind}/{idl.name}")
    args = out_dir / "args.json"
    args.write_text(json.dumps({"package_name": package, "output_dir": str(out_dir / "json"),
                                "idl_tuples": tuples, "include_paths": includes}))
    for json_path in g.generate_type_hash(str(args)):
        data = json.loads(pathlib.Path(json_path).read_text())
        for entry in data["type_hashes"]:
            result[entry["type_name"]] = entry["hash_string"]
        result["description:" + data["type_description_msg"]["type_description"]["type_name"]] = \
            data["type_description_msg"]
    includes.append(f"{package}:{out_dir / 'json'}")
json.dump(result, sys.stdout)
'''


def rosidl_hashes(distro: str, packages: Mapping[str, Iterable[Tuple[str, str, str]]],
                  timeout: float = 300.0) -> Dict[str, Any]:
    """Run rosidl on definitions: ``packages`` maps each package (in dependency order) to
    ``(kind, name, text)`` files. Returns ``{type name: RIHS01 hash}`` for every type rosidl
    describes, and ``{"description:" + top type: full description}`` per file."""
    share = ROS2_HOME / distro / "share"
    includes = [f"{p.name}:{p}" for p in sorted(share.iterdir())
                if (p / "msg").is_dir() or (p / "srv").is_dir()]
    with tempfile.TemporaryDirectory(prefix="minros-rosidl-") as tmp:
        root = Path(tmp)
        for package, files in packages.items():
            for kind, name, text in files:
                path = root / "src" / package / kind / f"{name}.{kind}"
                path.parent.mkdir(parents=True, exist_ok=True)
                path.write_text(text, encoding="utf-8")
        request = json.dumps({"root": str(root), "includes": includes,
                              "packages": list(packages)})
        run = subprocess.run([str(oracle_python(distro)), "-c", ROSIDL_ORACLE], input=request,
                             capture_output=True, text=True, timeout=timeout)
    if run.returncode != 0:
        raise RuntimeError(f"the rosidl oracle ({distro}) failed: {run.stderr[-3000:]}")
    result: Dict[str, Any] = json.loads(run.stdout)
    return result


# -- what a ROS 1 message becomes ----------------------------------------------------------------

_ROS1_CODES = {"int8": "b", "byte": "b", "uint8": "B", "char": "B", "int16": "h",
               "uint16": "H", "int32": "i", "uint32": "I", "int64": "q", "uint64": "Q"}


def ros2_plain_of_ros1(mapping: Any, obj: Any) -> Any:
    """The plain ROS 2 value a ROS 1 message object becomes under ``mapping`` (a
    :class:`~minros.ros2.types.mapping.MessageMapping`): what the converters must produce."""
    import struct

    from minros.msgs.codegen import python_name as ros1_attr

    reg = mapping.mapper.ros2
    struct_ = reg.message(mapping.ros2_type)
    if struct_.is_empty:
        return {}
    defaults = reg.codec(mapping.ros2_type).cls()
    out: Dict[str, Any] = {}

    def scalar(f1_base: str, t: FieldType, value: Any) -> Any:
        if t.base == "bool":
            return bool(value)
        if t.base in ("float32", "float64"):
            return float(value)
        if t.is_string:
            return value if isinstance(value, str) else bytes(value).decode()
        code1 = _ROS1_CODES.get(f1_base, "I")
        code2 = "B" if t.base == "byte" else _ROS1_CODES[t.base]  # ROS 2's byte: an octet
        return struct.unpack("<" + code2, struct.pack("<" + code1, value))[0]

    for link in mapping.links:
        f2 = link.ros2
        if link.ros1_path is None:
            out[f2.name] = _plain_field(reg, f2.type, getattr(defaults, python_name(f2.name)))
            continue
        value = obj
        for part in link.ros1_path:
            value = getattr(value, ros1_attr(part))
        f1 = link.ros1_field
        t = f2.type
        if link.nested is not None:
            out[f2.name] = [ros2_plain_of_ros1(link.nested, e) for e in value] if t.is_array \
                else ros2_plain_of_ros1(link.nested, value)
        elif t.is_array:
            if isinstance(value, (bytes, bytearray)):
                value = list(value)
            out[f2.name] = [scalar(f1.base_type, t.element(), v) for v in value]
        else:
            out[f2.name] = scalar(f1.base_type, t, value)
    return out
