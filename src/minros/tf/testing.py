"""Run the same tf work on minros and on Debian's tf2_py/tf (the reference), for tests and
benchmarks.

``TfOracle`` keeps one ``/usr/bin/python3`` process that answers JSON lines:

* ``{"op": "tx", "fn": NAME, "args": [...], "kwargs": {...}}``: call Debian's
  ``tf.transformations.NAME`` (``{"t": [...]}`` stands for a tuple, such as an axes tuple);
* ``{"op": "core", "actions": [...]}``: play a script of actions on a fresh Debian
  ``tf2_py.BufferCore`` (no ROS master needed) and return one result per action;
* ``{"op": "bench", "actions": [...], "queries": [...], "seconds": S}``: lookups per second
  of the queries on a BufferCore filled by the actions.

``play(core, actions)`` runs the same script on a minros ``BufferCore``, so a test compares
the two result lists. Actions (times are ``[secs, nsecs]``):

* ``["set", parent, child, t, [x, y, z], [qx, qy, qz, qw], authority, static]``
* ``["lookup", target, source, t]``, ``["can", target, source, t]``
* ``["full", target, t_target, source, t_source, fixed]``
* ``["lct", target, source]``, ``["yaml"]``, ``["string"]``, ``["clear"]``

A result is ``{"ok": value}`` or ``{"exc": class name, "msg": text}``; a lookup's value is
``[[secs, nsecs], frame_id, child_frame_id, [x, y, z, qx, qy, qz, qw]]``.
"""

from __future__ import annotations

import math
from typing import Any, Dict, List, Sequence

from minros.msgs.testing import ReferenceProcess, reference_script

ORACLE = reference_script(r'''
import json, math, sys
import rospy
import tf2_py
import tf.transformations as tft
from geometry_msgs.msg import TransformStamped

def plain(v):
    if hasattr(v, "tolist"):
        v = v.tolist()
    if isinstance(v, (list, tuple)):
        return [plain(x) for x in v]
    if isinstance(v, float) and not math.isfinite(v):
        return {"f": repr(v)}
    return v

def unplain(v):
    if isinstance(v, dict) and "f" in v:
        return float(v["f"])
    if isinstance(v, dict) and "t" in v:
        return tuple(v["t"])
    if isinstance(v, list):
        return [unplain(x) for x in v]
    return v

def stamped(parent, child, t, xyz, q):
    m = TransformStamped()
    m.header.frame_id = parent
    m.child_frame_id = child
    m.header.stamp = rospy.Time(t[0], t[1])
    tr = m.transform.translation
    tr.x, tr.y, tr.z = unplain(xyz)
    r = m.transform.rotation
    r.x, r.y, r.z, r.w = unplain(q)
    return m

def result_of(m):
    tr, r = m.transform.translation, m.transform.rotation
    return [[m.header.stamp.secs, m.header.stamp.nsecs], m.header.frame_id, m.child_frame_id,
            [tr.x, tr.y, tr.z, r.x, r.y, r.z, r.w]]

def T(t):
    return rospy.Time(t[0], t[1])

def run(core, a):
    op = a[0]
    if op == "set":
        m = stamped(a[1], a[2], a[3], a[4], a[5])
        if a[7]:
            core.set_transform_static(m, a[6])
        else:
            core.set_transform(m, a[6])
        return None
    if op == "lookup":
        return result_of(core.lookup_transform_core(a[1], a[2], T(a[3])))
    if op == "full":
        return result_of(core.lookup_transform_full_core(a[1], T(a[2]), a[3], T(a[4]), a[5]))
    if op == "can":
        ok, msg = core.can_transform_core(a[1], a[2], T(a[3]))
        return [bool(ok), msg]
    if op == "lct":
        t = core.get_latest_common_time(a[1], a[2])
        return [t.secs, t.nsecs]
    if op == "yaml":
        return core.all_frames_as_yaml()
    if op == "string":
        return core.all_frames_as_string()
    if op == "clear":
        core.clear()
        return None
    raise ValueError("unknown action %r" % (op,))

def play(actions):
    core = tf2_py.BufferCore()
    out = []
    for a in actions:
        try:
            out.append({"ok": plain(run(core, a))})
        except tf2_py.TransformException as exc:
            out.append({"exc": type(exc).__name__, "msg": str(exc)})
    return core, out

for line in sys.stdin:
    req = json.loads(line)
    try:
        if req["op"] == "tx":
            fn = getattr(tft, req["fn"])
            value = fn(*unplain(req.get("args", [])), **{k: unplain(v) for k, v in req.get("kwargs", {}).items()})
            out = {"value": plain(value)}
        elif req["op"] == "core":
            out = {"results": play(req["actions"])[1]}
        elif req["op"] == "bench":
            core, _ = play(req["actions"])
            queries = [(q[0], q[1], T(q[2])) for q in req["queries"]]
            lookup = core.lookup_transform_core
            def one_pass():
                for target, source, t in queries:
                    lookup(target, source, t)
            out = {"rate": best_rate(one_pass, req["seconds"], 0.01) * len(queries)}
        else:
            out = {"error": "unknown op"}
    except Exception as exc:
        out = {"error": "%s: %s" % (type(exc).__name__, exc)}
    sys.stdout.write(json.dumps(out) + "\n")
    sys.stdout.flush()
''')


# _plain, _stamped, result_of and play repeat the script's plain, stamped, result_of and
# run on purpose: the script runs under Debian's interpreter, which cannot import minros.
def _plain(value: Any) -> Any:
    if hasattr(value, "tolist"):
        value = value.tolist()
    if isinstance(value, (list, tuple)):
        return [_plain(v) for v in value]
    if isinstance(value, float) and not math.isfinite(value):
        return {"f": repr(value)}
    return value


class OracleError(RuntimeError):
    """The reference raised an exception that is not a tf2 one (reported as "Class: text")."""


class TfOracle(ReferenceProcess):
    """One long-lived Debian ``/usr/bin/python3`` answering tf requests (see module doc)."""

    def __init__(self, python: str = "/usr/bin/python3", env: Dict[str, str] | None = None,
                 timeout: float = 60.0) -> None:
        super().__init__(ORACLE, "tf oracle", python, env, timeout)

    def _answer(self, key: str, **req: Any) -> Any:
        """``answer[key]`` of the request; OracleError("Class: text") when the reference raised."""
        answer = self.request(**req)
        if "error" in answer:
            raise OracleError(answer["error"])
        return answer[key]

    def transformations(self, fn: str, *args: Any, **kwargs: Any) -> Any:
        """Debian's ``tf.transformations.fn(*args, **kwargs)`` as plain lists/floats;
        raises OracleError("Class: text") when it raised."""
        return self._answer("value", op="tx", fn=fn, args=_plain(list(args)),
                            kwargs={k: _plain(v) for k, v in kwargs.items()})

    def play(self, actions: Sequence[Any]) -> List[Dict[str, Any]]:
        """The results of ``actions`` on a fresh Debian tf2_py.BufferCore."""
        return self._answer("results", op="core", actions=_plain(list(actions)))

    def bench(self, actions: Sequence[Any], queries: Sequence[Any], seconds: float) -> float:
        """Debian's lookups per second over ``queries`` ([target, source, [secs, nsecs]])."""
        return self._answer("rate", op="bench", actions=_plain(list(actions)),
                            queries=_plain(list(queries)), seconds=seconds)


def _stamped(parent: str, child: str, t: Sequence[int], xyz: Sequence[float],
             q: Sequence[float]) -> Any:
    import minros
    from geometry_msgs.msg import TransformStamped

    m = TransformStamped()
    m.header.frame_id = parent
    m.child_frame_id = child
    m.header.stamp = minros.Time(t[0], t[1])
    tr = m.transform.translation
    tr.x, tr.y, tr.z = xyz
    r = m.transform.rotation
    r.x, r.y, r.z, r.w = q
    return m


def result_of(m: Any) -> List[Any]:
    """A TransformStamped as ``[[secs, nsecs], frame_id, child_frame_id, [x..w]]``."""
    tr, r = m.transform.translation, m.transform.rotation
    return [[m.header.stamp.secs, m.header.stamp.nsecs], m.header.frame_id, m.child_frame_id,
            [tr.x, tr.y, tr.z, r.x, r.y, r.z, r.w]]


def play(core: Any, actions: Sequence[Any]) -> List[Dict[str, Any]]:
    """Run an action script on a minros BufferCore; same result format as the oracle's."""
    import minros

    from .exceptions import TransformException

    def time_of(t: Sequence[int]) -> Any:
        return minros.Time(t[0], t[1])

    out: List[Dict[str, Any]] = []
    for a in actions:
        op = a[0]
        try:
            if op == "set":
                m = _stamped(a[1], a[2], a[3], a[4], a[5])
                if a[7]:
                    core.set_transform_static(m, a[6])
                else:
                    core.set_transform(m, a[6])
                value: Any = None
            elif op == "lookup":
                value = result_of(core.lookup_transform_core(a[1], a[2], time_of(a[3])))
            elif op == "full":
                value = result_of(core.lookup_transform_full_core(
                    a[1], time_of(a[2]), a[3], time_of(a[4]), a[5]))
            elif op == "can":
                ok, msg = core.can_transform_core(a[1], a[2], time_of(a[3]))
                value = [bool(ok), msg]
            elif op == "lct":
                t = core.get_latest_common_time(a[1], a[2])
                value = [t.secs, t.nsecs]
            elif op == "yaml":
                value = core.all_frames_as_yaml()
            elif op == "string":
                value = core.all_frames_as_string()
            elif op == "clear":
                core.clear()
                value = None
            else:
                raise ValueError(f"unknown action {op!r}")
            out.append({"ok": _plain(value)})
        except TransformException as exc:
            out.append({"exc": type(exc).__name__, "msg": str(exc)})
    return out
