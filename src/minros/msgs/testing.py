"""Test helpers for message types: hypothesis strategies, plain-data conversion, a genpy oracle.

Used by minros's own tests and benchmarks (and usable by anyone testing code that handles
messages). Importing this module needs ``hypothesis`` only when a strategy is requested.

The genpy oracle is a small script run by Debian's ``/usr/bin/python3``
(:class:`ReferenceProcess`, which minros.tf.testing's oracle uses too): it reads one JSON
request per line (``{"op": "ser", "type": ..., "value": ...}`` or ``{"op": "de", "type": ...,
"hex": ...}``) and answers one JSON line, so one long-lived process serves a whole test run.
"""

from __future__ import annotations

import inspect
import json
import math
import os
import selectors
import subprocess
import time
from typing import Any, Callable, Dict, List

from .registry import REGISTRY, MsgContext
from .spec import split_array
from .tval import Duration, Time

_INT_RANGES = {
    "int8": (-(2 ** 7), 2 ** 7 - 1), "byte": (-(2 ** 7), 2 ** 7 - 1), "uint8": (0, 255),
    "char": (0, 255), "int16": (-(2 ** 15), 2 ** 15 - 1), "uint16": (0, 2 ** 16 - 1),
    "int32": (-(2 ** 31), 2 ** 31 - 1), "uint32": (0, 2 ** 32 - 1),
    "int64": (-(2 ** 63), 2 ** 63 - 1), "uint64": (0, 2 ** 64 - 1),
}


def strategy_for(type_name: str, context: MsgContext | None = None, max_array: int = 3) -> Any:
    """A hypothesis strategy producing instances of message type ``type_name``."""
    from hypothesis import strategies as st

    ctx = context or REGISTRY
    cache: Dict[str, Any] = {}

    def field_strategy(type_: str):
        base, is_array, length = split_array(type_)
        if is_array:
            if base in ("uint8", "char"):
                if length is None:
                    return st.binary(max_size=max_array * 4)
                return st.binary(min_size=length, max_size=length)
            item = field_strategy(base)
            if length is None:
                return st.lists(item, max_size=max_array)
            return st.lists(item, min_size=length, max_size=length)
        if base in _INT_RANGES:
            lower, upper = _INT_RANGES[base]
            return st.integers(lower, upper)
        if base == "float64":
            return st.floats(allow_nan=False)
        if base == "float32":
            return st.floats(allow_nan=False, width=32)
        if base == "bool":
            return st.booleans()
        if base == "string":
            surrogates: Any = ("Cs",)  # not UTF-8 encodable
            return st.text(st.characters(blacklist_categories=surrogates), max_size=12)
        if base == "time":
            return st.builds(Time, st.integers(0, 2 ** 32 - 1), st.integers(0, 999999999))
        if base == "duration":
            return st.builds(Duration, st.integers(-(2 ** 31), 2 ** 31 - 1), st.integers(0, 999999999))
        return message_strategy(base)

    def message_strategy(name: str):
        if name not in cache:
            cls: Any = ctx.get_class(name)
            spec = ctx.get_spec(name)
            fields = {attr: field_strategy(t) for attr, t in zip(cls.__slots__, spec.types)}
            cache[name] = st.builds(cls, **fields)
        return cache[name]

    return message_strategy(type_name)


def to_plain(value: Any) -> Any:
    """JSON-able form of a message value: dicts, lists, ``[secs, nsecs]``, ``{"b": hex}``."""
    if hasattr(value, "_slot_types") and hasattr(value, "_type"):
        return {name: to_plain(getattr(value, name)) for name in value.__slots__}
    if isinstance(value, (Time, Duration)):
        return [value.secs, value.nsecs]
    if isinstance(value, (bytes, bytearray, memoryview)):
        return {"b": bytes(value).hex()}
    if isinstance(value, (list, tuple)):
        return [to_plain(v) for v in value]
    if isinstance(value, float) and not math.isfinite(value):
        return {"f": repr(value)}
    return value


def best_rate(fn: Callable[[], Any], seconds: float, batch_seconds: float = 0.002) -> float:
    """Calls per second of ``fn`` in its fastest batch of about ``batch_seconds``, batches
    repeated for ``seconds``: the best batch, not the mean, so that other processes on a busy
    machine distort the figure least. Every speed comparison of minros measures this way, on
    both sides (the scripts Debian's interpreter runs define it from :data:`BEST_RATE_SOURCE`)."""
    batch, best, deadline = 1, 0.0, time.perf_counter() + seconds
    while True:
        start = time.perf_counter()
        for _ in range(batch):
            fn()
        elapsed = time.perf_counter() - start
        if elapsed > 0:
            best = max(best, batch / elapsed)
        if elapsed < batch_seconds:
            batch *= 2
        if time.perf_counter() > deadline:
            return best


#: the text of :func:`best_rate`, for scripts run where minros cannot be imported
BEST_RATE_SOURCE = inspect.getsource(best_rate)


def reference_script(body: str) -> str:
    """``body``, a script for Debian's interpreter, with :func:`best_rate` defined before it
    (its annotations left unevaluated: the script does not import their names)."""
    return "from __future__ import annotations\nimport time\n" + BEST_RATE_SOURCE + body


GENPY_ORACLE = reference_script(r'''
import importlib, json, math, sys, io, time
import genpy

def find_class(type_name):
    pkg, name = type_name.split("/")
    for kind in ("msg", "srv"):
        try:
            mod = importlib.import_module(pkg + "." + kind)
        except ImportError:
            continue
        cls = getattr(mod, name, None)
        if cls is not None and hasattr(cls, "_slot_types"):
            return cls
    raise KeyError(type_name)

def build(cls, plain):
    msg = cls()
    for name, type_ in zip(cls.__slots__, cls._slot_types):
        setattr(msg, name, value_of(type_, plain[name]))
    return msg

def value_of(type_, plain):
    base = type_.split("[")[0]
    if "[" in type_:
        if base in ("uint8", "char"):
            return bytes.fromhex(plain["b"])
        return [value_of(base, v) for v in plain]
    if base == "time":
        return genpy.Time(*plain)
    if base == "duration":
        return genpy.Duration(*plain)
    if isinstance(plain, dict) and "f" in plain:
        return float(plain["f"])
    if base in ("float32", "float64"):
        return float(plain)
    if isinstance(plain, dict):
        if base == "Header":
            base = "std_msgs/Header"
        return build(find_class(base), plain)
    return plain

def plain_of(value):
    if isinstance(value, genpy.Message):
        return {n: plain_of(getattr(value, n)) for n in value.__slots__}
    if isinstance(value, (genpy.Time, genpy.Duration)):
        return [value.secs, value.nsecs]
    if isinstance(value, bytes):
        return {"b": value.hex()}
    if isinstance(value, (list, tuple)):
        return [plain_of(v) for v in value]
    if isinstance(value, float) and not math.isfinite(value):
        return {"f": repr(value)}
    return value

for line in sys.stdin:
    req = json.loads(line)
    try:
        cls = find_class(req["type"])
        if req["op"] == "ser":
            buf = io.BytesIO()
            build(cls, req["value"]).serialize(buf)
            out = {"hex": buf.getvalue().hex()}
        elif req["op"] == "de":
            out = {"value": plain_of(cls().deserialize(bytes.fromhex(req["hex"])))}
        elif req["op"] == "bench":
            msg = build(cls, req["value"])
            buf = io.BytesIO(); msg.serialize(buf); data = buf.getvalue()
            def ser():
                msg.serialize(io.BytesIO())
            def de():
                cls().deserialize(data)
            out = {"ser": best_rate(ser, req["seconds"]), "de": best_rate(de, req["seconds"]),
                   "size": len(data)}
        else:
            out = {"error": "unknown op"}
    except Exception as exc:
        out = {"error": "%s: %s" % (type(exc).__name__, exc)}
    sys.stdout.write(json.dumps(out) + "\n")
    sys.stdout.flush()
''')


class ReferenceProcess:
    """One long-lived process (by default Debian's ``/usr/bin/python3``) running ``script``,
    which answers each JSON line it reads with one JSON line; ``name`` is what errors call it."""

    def __init__(self, script: str, name: str, python: str = "/usr/bin/python3",
                 env: Dict[str, str] | None = None, timeout: float = 30.0) -> None:
        self.name = name
        self.timeout = timeout
        self.proc = subprocess.Popen(
            [python, "-c", script], stdin=subprocess.PIPE, stdout=subprocess.PIPE,
            stderr=subprocess.DEVNULL, env=env, text=True, bufsize=1)
        self._selector = selectors.DefaultSelector()
        assert self.proc.stdout is not None
        self._selector.register(self.proc.stdout, selectors.EVENT_READ)

    def request(self, **req: Any) -> Dict[str, Any]:
        assert self.proc.stdin is not None and self.proc.stdout is not None
        self.proc.stdin.write(json.dumps(req) + "\n")
        self.proc.stdin.flush()
        if not self._selector.select(self.timeout):
            raise TimeoutError(f"{self.name} did not answer within {self.timeout} s")
        line = self.proc.stdout.readline()
        if not line:
            raise RuntimeError(f"{self.name} exited")
        return json.loads(line)

    def close(self) -> None:
        try:
            if self.proc.stdin:
                self.proc.stdin.close()
            self.proc.wait(5)
        except (OSError, subprocess.TimeoutExpired):
            self.proc.kill()
            self.proc.wait(5)
        self._selector.close()


class GenpyOracle(ReferenceProcess):
    """One long-lived ``/usr/bin/python3`` process answering genpy (de)serialization requests."""

    def __init__(self, python: str = "/usr/bin/python3", env: Dict[str, str] | None = None,
                 timeout: float = 30.0) -> None:
        super().__init__(GENPY_ORACLE, "genpy oracle", python, env, timeout)

    def serialize(self, type_name: str, msg: Any) -> bytes:
        answer = self.request(op="ser", type=type_name, value=to_plain(msg))
        if "error" in answer:
            raise RuntimeError(f"genpy failed on {type_name}: {answer['error']}")
        return bytes.fromhex(answer["hex"])

    def deserialize(self, type_name: str, data: bytes) -> Any:
        answer = self.request(op="de", type=type_name, hex=data.hex())
        if "error" in answer:
            raise RuntimeError(f"genpy failed on {type_name}: {answer['error']}")
        return answer["value"]


def bundled_types() -> List[str]:
    """Every message type (including service request/response types) minros ships."""
    from minros.packages import BUILTIN_SHARE_DIRS

    names: List[str] = []
    for root in BUILTIN_SHARE_DIRS:
        for package in sorted(os.listdir(root)):
            for kind in ("msg", "srv"):
                folder = root / package / kind
                if not folder.is_dir():
                    continue
                for file in sorted(os.listdir(folder)):
                    stem, ext = os.path.splitext(file)
                    if ext == ".msg" and kind == "msg":
                        names.append(f"{package}/{stem}")
                    elif ext == ".srv" and kind == "srv":
                        names += [f"{package}/{stem}Request", f"{package}/{stem}Response"]
    return names


def bundled_services() -> List[str]:
    from minros.packages import BUILTIN_SHARE_DIRS

    names: List[str] = []
    for root in BUILTIN_SHARE_DIRS:
        for package in sorted(os.listdir(root)):
            folder = root / package / "srv"
            if folder.is_dir():
                names += [f"{package}/{f[:-4]}" for f in sorted(os.listdir(folder)) if f.endswith(".srv")]
    return names
