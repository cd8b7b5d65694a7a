"""Run the same PyKDL code on minros.kdl and on Debian's python3-pykdl, for tests and
benchmarks.

``KdlOracle`` keeps one ``/usr/bin/python3`` process with Debian's PyKDL that answers JSON
lines: ``{"op": "eval", "items": [[code, env], ...]}`` runs each ``code`` (Python source whose
last statement, when it is an expression, gives the answer, else the variable ``result``)
with ``K`` bound to PyKDL, ``math`` imported and ``env``'s plain values in scope, and returns
one plain result per item (an item ``[setup, env, snippets]`` runs ``setup`` once and answers
a list, one result per snippet, each run in a copy of setup's scope);
``{"op": "bench", "setup": code, "stmts": {name: code}, "seconds": s}`` returns calls per
second of each statement (minros.msgs.testing.best_rate). ``evaluate(items)`` does the same
with minros.kdl in this process, so a test compares two lists.

A plain result is JSON: numbers, lists, ``{"type": class name, "v": [...]}`` for KDL objects
(their numbers in KDL's order), ``{"exc": class name}`` for an exception, ``{"f": "nan"}``
for a number JSON cannot hold.
"""

from __future__ import annotations

import math
from typing import Any, Dict, List, Sequence

from minros.msgs.testing import ReferenceProcess, reference_script

#: the conversion to plain data, run on both sides (Debian's objects and ours expose the
#: same public methods, so one text serves both)
PLAIN_SOURCE = r'''
import ast
import math

def _num(x):
    x = float(x)
    return x if math.isfinite(x) else {"f": repr(x)}

def plain(v, K):
    name = type(v).__name__
    if isinstance(v, bool) or v is None or isinstance(v, str):
        return v
    if isinstance(v, int):
        return v
    if isinstance(v, float):
        return _num(v)
    if isinstance(v, (list, tuple)):
        return [plain(x, K) for x in v]
    if name == "Vector":
        return {"type": name, "v": [_num(v[i]) for i in range(3)]}
    if name in ("Twist", "Wrench"):
        return {"type": name, "v": [_num(v[i]) for i in range(6)]}
    if name == "Rotation":
        return {"type": name, "v": [_num(v[i, j]) for i in range(3) for j in range(3)]}
    if name == "Frame":
        return {"type": name, "v": [_num(v[i, j]) for i in range(3) for j in range(4)]}
    if name == "JntArray":
        return {"type": name, "v": [_num(v[i]) for i in range(v.rows())]}
    if name == "Jacobian":
        return {"type": name, "v": [[_num(v[i, j]) for j in range(v.columns())] for i in range(v.rows())]}
    if name == "JntSpaceInertiaMatrix":
        return {"type": name, "v": [[_num(v[i, j]) for j in range(v.columns())] for i in range(v.rows())]}
    if name == "doubleVel":
        return {"type": name, "v": [_num(v.t), _num(v.grad)]}
    if name in ("VectorVel", "RotationVel", "FrameVel", "TwistVel"):
        return {"type": name, "v": [plain(v.value(), K), plain(v.deriv(), K)]}
    if name == "JntArrayVel":
        return {"type": name, "v": [plain(v.q, K), plain(v.qdot, K)]}
    if name == "RotationalInertia":
        return {"type": name, "v": [_num(v[i]) for i in range(9)]}
    if name == "RigidBodyInertia":
        return {"type": name, "v": [_num(v.getMass()), plain(v.getCOG(), K),
                                    plain(v.getRotationalInertia(), K)]}
    if name == "Joint":
        return {"type": name, "v": [v.getName(), v.getTypeName(), plain(v.JointAxis(), K),
                                    plain(v.JointOrigin(), K)]}
    if name == "Segment":
        return {"type": name, "v": [v.getName(), plain(v.getJoint(), K),
                                    plain(v.getFrameToTip(), K), plain(v.getInertia(), K)]}
    if name == "Chain":
        return {"type": name, "v": [plain(v.getSegment(i), K) for i in range(v.getNrOfSegments())]}
    if name == "JointType":
        return {"type": name, "v": int(v)}
    return {"type": name, "v": repr(v)}

def unplain(v, K):
    """Inputs: {"Vector": [...]}, {"Rotation": [...]}, {"Frame": [...]}, ... become objects."""
    if isinstance(v, list):
        return [unplain(x, K) for x in v]
    if isinstance(v, dict):
        (kind, args), = v.items()
        if kind == "f":
            return float(args)
        if kind == "Vector":
            return K.Vector(*args)
        if kind == "Rotation":
            return K.Rotation(*args)
        if kind == "Frame":
            return K.Frame(K.Rotation(*args[:9]), K.Vector(*args[9:]))
        if kind in ("Twist", "Wrench"):
            return getattr(K, kind)(K.Vector(*args[:3]), K.Vector(*args[3:]))
        if kind == "JntArray":
            q = K.JntArray(len(args))
            for i, x in enumerate(args):
                q[i] = x
            return q
        if kind == "tuple":
            return tuple(unplain(x, K) for x in args)
        raise ValueError("unknown input kind " + kind)
    return v

def run(code, scope, K):
    """``code``'s answer: its last statement when that is an expression, else ``result``."""
    try:
        tree = ast.parse(code)
        last = tree.body.pop() if tree.body and isinstance(tree.body[-1], ast.Expr) else None
        exec(compile(tree, "<kdl>", "exec"), scope)
        if last is None:
            value = scope.get("result")
        else:
            value = eval(compile(ast.Expression(last.value), "<kdl>", "eval"), scope)
        return plain(value, K)
    except Exception as exc:
        return {"exc": type(exc).__name__}

def evaluate(items, K):
    """One answer per item: [code, env] gives code's answer; [setup, env, snippets] runs
    setup once and answers a list, one per snippet (each in a copy of setup's scope)."""
    out = []
    for item in items:
        code, env = item[0], item[1]
        scope = {"K": K, "math": math}
        scope.update({k: unplain(v, K) for k, v in env.items()})
        if len(item) == 2:
            out.append(run(code, scope, K))
            continue
        failed = run(code, scope, K)
        if isinstance(failed, dict) and "exc" in failed:
            out.append([failed] * len(item[2]))
        else:
            out.append([run(snippet, dict(scope), K) for snippet in item[2]])
    return out
'''

_ORACLE = reference_script(PLAIN_SOURCE + r'''
import json, sys
import PyKDL

for line in sys.stdin:
    req = json.loads(line)
    try:
        if req["op"] == "eval":
            answer = {"results": evaluate(req["items"], PyKDL)}
        elif req["op"] == "bench":
            scope = {"K": PyKDL, "math": math}
            exec(req["setup"], scope)
            rates = {}
            for name, stmt in req["stmts"].items():
                fn = eval("lambda: " + stmt, scope)
                rates[name] = best_rate(fn, req["seconds"])
            answer = {"rates": rates}
        else:
            answer = {"error": "unknown op"}
    except Exception as exc:
        answer = {"error": "%s: %s" % (type(exc).__name__, exc)}
    sys.stdout.write(json.dumps(answer) + "\n")
    sys.stdout.flush()
''')

_local: Dict[str, Any] = {}
exec(PLAIN_SOURCE, _local)  # noqa: S102 (our own text, the one the oracle runs)


class KdlOracle(ReferenceProcess):
    """One long-lived ``/usr/bin/python3`` with Debian's PyKDL (see the module's text)."""

    def __init__(self, python: str = "/usr/bin/python3", env: Dict[str, str] | None = None,
                 timeout: float = 60.0) -> None:
        super().__init__(_ORACLE, "PyKDL oracle", python, env, timeout)

    def evaluate(self, items: Sequence[Sequence[Any]]) -> List[Any]:
        answer = self.request(op="eval", items=[list(item) for item in items])
        if "error" in answer:
            raise RuntimeError(f"the PyKDL oracle failed: {answer['error']}")
        return answer["results"]

    def bench(self, setup: str, stmts: Dict[str, str], seconds: float) -> Dict[str, float]:
        answer = self.request(op="bench", setup=setup, stmts=stmts, seconds=seconds)
        if "error" in answer:
            raise RuntimeError(f"the PyKDL oracle failed: {answer['error']}")
        return answer["rates"]


def evaluate(items: Sequence[Sequence[Any]]) -> List[Any]:
    """The oracle's answer computed with minros.kdl in this process."""
    from minros import kdl

    return _local["evaluate"](items, kdl)


def differences(ours: Any, theirs: Any, tol: float = 1e-9, path: str = "") -> List[str]:
    """Where two plain results differ (numbers within ``tol``, relative above 1)."""
    if isinstance(ours, dict) and isinstance(theirs, dict):
        if set(ours) != set(theirs):
            return [f"{path}: {ours} vs {theirs}"]
        out: List[str] = []
        for key in ours:
            out += differences(ours[key], theirs[key], tol, f"{path}.{key}")
        return out
    if isinstance(ours, list) and isinstance(theirs, list):
        if len(ours) != len(theirs):
            return [f"{path}: length {len(ours)} vs {len(theirs)}"]
        out = []
        for i, (a, b) in enumerate(zip(ours, theirs)):
            out += differences(a, b, tol, f"{path}[{i}]")
        return out
    if isinstance(ours, float) or isinstance(theirs, float):
        if isinstance(ours, bool) or isinstance(theirs, bool):
            return [] if ours == theirs else [f"{path}: {ours} vs {theirs}"]
        try:
            a, b = float(ours), float(theirs)
        except (TypeError, ValueError):
            return [f"{path}: {ours!r} vs {theirs!r}"]
        if math.isclose(a, b, rel_tol=tol, abs_tol=tol):
            return []
        return [f"{path}: {a!r} vs {b!r}"]
    return [] if ours == theirs else [f"{path}: {ours!r} vs {theirs!r}"]
