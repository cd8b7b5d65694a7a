"""PyKDL's module functions, overloaded on their arguments' types as in KDL: diff, addDelta,
dot, Equal, SetToZero, the JntArray arithmetic (Add, Subtract, Multiply, Divide, written into
their last argument), MultiplyJacobian, changeBase and changeRefPoint.

Each function looks its implementation up by the classes of its arguments; a combination KDL
does not define is a TypeError that lists the ones it does.
"""

from __future__ import annotations

from typing import Any, Callable, Dict, Sequence, Tuple

from .frames import (
    EPSILON,
    Frame,
    Rotation,
    Twist,
    Vector,
    Wrench,
    _close,
    _divide,
    _frame,
    _rot_angle,
    _rot_mul,
    _rot_rot,
    _rot_vector,
    _rotation,
    _transpose,
    _twist,
    _vector,
    _wrench,
)
from .framevel import FrameVel, RotationVel, TwistVel, VectorVel, _dv, doubleVel
from .kinfam import (
    Jacobian,
    JntArray,
    JntArrayVel,
    JntSpaceInertiaMatrix,
    _col_frame,
    _col_refpoint,
    _col_rotate,
    _within,
)

__all__ = ["diff", "addDelta", "dot", "Equal", "SetToZero", "Add", "Subtract", "Multiply",
           "Divide", "MultiplyJacobian", "changeBase", "changeRefPoint"]


def _dispatch(name: str, table: Dict[Tuple[type, ...], Callable], args: Sequence[Any]) -> Callable:
    key = tuple(type(a) for a in args)
    fn = table.get(key)
    if fn is None:
        for types, candidate in table.items():
            if len(types) == len(args) and all(isinstance(a, t) for a, t in zip(args, types)):
                return candidate
        accepted = "; ".join("(" + ", ".join(t.__name__ for t in types) + ")" for types in table)
        got = ", ".join(type(a).__name__ for a in args)
        raise TypeError(f"{name}() takes one of {accepted}; got ({got})")
    return fn


# ----------------------------------------------------------------------------------- diff

def _diff_vectors(a: Sequence[float], b: Sequence[float], dt: float) -> list:
    return _divide([b[0] - a[0], b[1] - a[1], b[2] - a[2]], dt)


def _diff_rotations(a: Sequence[float], b: Sequence[float], dt: float) -> list:
    angle, (x, y, z) = _rot_angle(_rot_rot(_transpose(a), b))
    return _divide(_rot_mul(a, [x * angle, y * angle, z * angle]), dt)


_DIFF: Dict[Tuple[type, ...], Callable] = {
    (Vector, Vector): lambda a, b, dt: _vector(*_diff_vectors(a._d, b._d, dt)),
    (Rotation, Rotation): lambda a, b, dt: _vector(*_diff_rotations(a._d, b._d, dt)),
    (Frame, Frame): lambda a, b, dt: _twist(_diff_vectors(a._p._d, b._p._d, dt),
                                            _diff_rotations(a._M._d, b._M._d, dt)),
    (Twist, Twist): lambda a, b, dt: _twist(_diff_vectors(a._vel._d, b._vel._d, dt),
                                            _diff_vectors(a._rot._d, b._rot._d, dt)),
    (Wrench, Wrench): lambda a, b, dt: _wrench(_diff_vectors(a._force._d, b._force._d, dt),
                                               _diff_vectors(a._torque._d, b._torque._d, dt)),
    (doubleVel, doubleVel): lambda a, b, dt: _dv((b.t - a.t) / dt, (b.grad - a.grad) / dt),
    (VectorVel, VectorVel): lambda a, b, dt: _vvel(_diff_vectors(a._p._d, b._p._d, dt),
                                                   _diff_vectors(a._v._d, b._v._d, dt)),
    (RotationVel, RotationVel): lambda a, b, dt: _vvel(_diff_rotations(a._R._d, b._R._d, dt),
                                                       _diff_vectors(a._w._d, b._w._d, dt)),
    # KDL pairs the rotation's difference with vel and the position's with rot (see framevel)
    (FrameVel, FrameVel): lambda a, b, dt: TwistVel(diff(a._M, b._M, dt), diff(a._p, b._p, dt)),
}


def _vvel(p: list, v: list) -> VectorVel:
    return VectorVel(_vector(*p), _vector(*v))


def diff(a: Any, b: Any, dt: float = 1.0) -> Any:
    """The velocity that takes ``a`` to ``b`` in time ``dt``: (b - a) / dt for vectors, twists
    and wrenches; for rotations the rotation vector of a^-1 b expressed in a's base frame;
    for frames the Twist of both."""
    return _dispatch("diff", _DIFF, (a, b))(a, b, float(dt))


# ------------------------------------------------------------------------------- addDelta

def _add_vectors(a: Sequence[float], da: Sequence[float], dt: float) -> list:
    return [a[0] + da[0] * dt, a[1] + da[1] * dt, a[2] + da[2] * dt]


def _add_rotation(a: Sequence[float], da: Sequence[float], dt: float) -> list:
    return _rot_rot(_rot_vector(da[0] * dt, da[1] * dt, da[2] * dt), a)


_ADD_DELTA: Dict[Tuple[type, ...], Callable] = {
    (Vector, Vector): lambda a, da, dt: _vector(*_add_vectors(a._d, da._d, dt)),
    (Rotation, Vector): lambda a, da, dt: _rotation(_add_rotation(a._d, da._d, dt)),
    (Frame, Twist): lambda a, da, dt: _frame(_add_rotation(a._M._d, da._rot._d, dt),
                                             _add_vectors(a._p._d, da._vel._d, dt)),
    (Twist, Twist): lambda a, da, dt: _twist(_add_vectors(a._vel._d, da._vel._d, dt),
                                             _add_vectors(a._rot._d, da._rot._d, dt)),
    (Wrench, Wrench): lambda a, da, dt: _wrench(_add_vectors(a._force._d, da._force._d, dt),
                                                _add_vectors(a._torque._d, da._torque._d, dt)),
    (doubleVel, doubleVel): lambda a, da, dt: _dv(a.t + da.t * dt, a.grad + da.grad * dt),
    (VectorVel, VectorVel): lambda a, da, dt: _vvel(_add_vectors(a._p._d, da._p._d, dt),
                                                    _add_vectors(a._v._d, da._v._d, dt)),
    (RotationVel, VectorVel): lambda a, da, dt: RotationVel(
        _rotation(_add_rotation(a._R._d, da._p._d, dt)), _vector(*_add_vectors(a._w._d, da._v._d, dt))),
    (FrameVel, TwistVel): lambda a, da, dt: FrameVel(addDelta(a._M, da._rot, dt),
                                                     addDelta(a._p, da._vel, dt)),
}


def addDelta(a: Any, da: Any, dt: float = 1.0) -> Any:  # noqa: N802 (KDL's name)
    """``a`` moved by velocity ``da`` for time ``dt`` (the inverse of diff)."""
    return _dispatch("addDelta", _ADD_DELTA, (a, da))(a, da, float(dt))


# ------------------------------------------------------------------------------------ dot

def _dot3(a: Sequence[float], b: Sequence[float]) -> float:
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]


_DOT: Dict[Tuple[type, ...], Callable] = {
    (Vector, Vector): lambda a, b: _dot3(a._d, b._d),
    (Twist, Wrench): lambda t, w: _dot3(t._vel._d, w._force._d) + _dot3(t._rot._d, w._torque._d),
    (Wrench, Twist): lambda w, t: _dot3(t._vel._d, w._force._d) + _dot3(t._rot._d, w._torque._d),
    (VectorVel, VectorVel): lambda a, b: _dv(_dot3(a._p._d, b._p._d),
                                             _dot3(a._p._d, b._v._d) + _dot3(a._v._d, b._p._d)),
    (VectorVel, Vector): lambda a, b: _dv(_dot3(a._p._d, b._d), _dot3(a._v._d, b._d)),
    (Vector, VectorVel): lambda a, b: _dv(_dot3(a._d, b._p._d), _dot3(a._d, b._v._d)),
}


def dot(a: Any, b: Any) -> Any:
    """The dot product of two Vectors, the power of a Twist and a Wrench, or their
    doubleVel for VectorVels."""
    return _dispatch("dot", _DOT, (a, b))(a, b)


# ---------------------------------------------------------------------------------- Equal

_ZERO = (0.0, 0.0, 0.0)


def _eq_vv(a: VectorVel, b: VectorVel, eps: float) -> bool:
    return _close(a._p._d, b._p._d, eps) and _close(a._v._d, b._v._d, eps)


def _eq_v_vv(a: Vector, b: VectorVel, eps: float) -> bool:
    return _close(a._d, b._p._d, eps) and _close(_ZERO, b._v._d, eps)


def _eq_rv(a: RotationVel, b: RotationVel, eps: float) -> bool:
    return _close(a._w._d, b._w._d, eps) and _close(a._R._d, b._R._d, eps)


def _eq_r_rv(a: Rotation, b: RotationVel, eps: float) -> bool:
    return _close(_ZERO, b._w._d, eps) and _close(a._d, b._R._d, eps)


def _eq_frames(a: Frame, b: Frame, eps: float) -> bool:
    return _close(a._M._d, b._M._d, eps) and _close(a._p._d, b._p._d, eps)


def _eq_twists(a: Any, b: Any, eps: float) -> bool:
    """Two screws (Twist/Wrench) side by side."""
    (a1, a2), (b1, b2) = a._pair(), b._pair()
    return _close(a1, b1, eps) and _close(a2, b2, eps)


def _eq_tv(a: TwistVel, b: TwistVel, eps: float) -> bool:
    return _eq_vv(a._rot, b._rot, eps) and _eq_vv(a._vel, b._vel, eps)


def _eq_t_tv(a: Twist, b: TwistVel, eps: float) -> bool:
    return _eq_v_vv(a._rot, b._rot, eps) and _eq_v_vv(a._vel, b._vel, eps)


def _eq_fv(a: FrameVel, b: FrameVel, eps: float) -> bool:
    return _eq_rv(a._M, b._M, eps) and _eq_vv(a._p, b._p, eps)


def _eq_f_fv(a: Frame, b: FrameVel, eps: float) -> bool:
    return _eq_r_rv(a._M, b._M, eps) and _eq_v_vv(a._p, b._p, eps)


def _eq_jnt(a: JntArray, b: JntArray, eps: float) -> bool:
    return len(a._d) == len(b._d) and _within(a._d, b._d, eps)


_EQUAL: Dict[Tuple[type, ...], Callable] = {
    (Vector, Vector): lambda a, b, eps: _close(a._d, b._d, eps),
    (Wrench, Wrench): _eq_twists,
    (Twist, Twist): _eq_twists,
    (Rotation, Rotation): lambda a, b, eps: _close(a._d, b._d, eps),
    (Frame, Frame): _eq_frames,
    (doubleVel, doubleVel): lambda a, b, eps: _close((a.t, a.grad), (b.t, b.grad), eps),
    (VectorVel, VectorVel): _eq_vv,
    (Vector, VectorVel): _eq_v_vv,
    (VectorVel, Vector): lambda a, b, eps: _eq_v_vv(b, a, eps),
    (TwistVel, TwistVel): _eq_tv,
    (Twist, TwistVel): _eq_t_tv,
    (TwistVel, Twist): lambda a, b, eps: _eq_t_tv(b, a, eps),
    (RotationVel, RotationVel): _eq_rv,
    (Rotation, RotationVel): _eq_r_rv,
    (RotationVel, Rotation): lambda a, b, eps: _eq_r_rv(b, a, eps),
    (FrameVel, FrameVel): _eq_fv,
    (Frame, FrameVel): _eq_f_fv,
    (FrameVel, Frame): lambda a, b, eps: _eq_f_fv(b, a, eps),
    (JntArray, JntArray): _eq_jnt,
    (JntArrayVel, JntArrayVel): lambda a, b, eps: (_eq_jnt(a._q, b._q, eps)
                                                   and _eq_jnt(a._qdot, b._qdot, eps)),
    (JntSpaceInertiaMatrix, JntSpaceInertiaMatrix): lambda a, b, eps: (
        len(a._r) == len(b._r) and all(_within(x, y, eps) for x, y in zip(a._r, b._r))),
}


def Equal(*args: Any, **kwargs: Any) -> bool:  # noqa: N802
    """Whether two objects of the same kind are equal within ``eps`` (default 1e-6), element
    by element: ``Equal(a, b, eps=1e-6)``."""
    names = (("a", "r1", "src1"), ("b", "r2", "src2"), ("eps",))
    values = list(args)
    for slot in names[len(values):]:
        for name in slot:
            if name in kwargs:
                values.append(kwargs.pop(name))
                break
        else:
            break
    if kwargs or len(values) not in (2, 3):
        raise TypeError("Equal() takes (a, b) or (a, b, eps)")
    a, b = values[:2]
    eps = float(values[2]) if len(values) == 3 else EPSILON
    return _dispatch("Equal", _EQUAL, (a, b))(a, b, eps)


# ------------------------------------------------------------------------------ SetToZero

def _zero_vector(v: Vector) -> None:
    v._d = [0.0, 0.0, 0.0]


def _zero_screw(s: Any) -> None:
    for part in s._pair():
        part[0] = part[1] = part[2] = 0.0


def _zero_vv(v: VectorVel) -> None:
    v._p._d, v._v._d = [0.0, 0.0, 0.0], [0.0, 0.0, 0.0]


def _zero_jac(j: Jacobian) -> None:
    j._c = [[0.0] * 6 for _ in j._c]


_SET_TO_ZERO: Dict[Tuple[type, ...], Callable] = {
    (Vector,): _zero_vector,
    (Wrench,): _zero_screw,
    (Twist,): _zero_screw,
    (VectorVel,): _zero_vv,
    (TwistVel,): lambda t: (_zero_vv(t._vel), _zero_vv(t._rot)),
    (Jacobian,): _zero_jac,
    (JntArray,): lambda j: setattr(j, "_d", [0.0] * len(j._d)),
    (JntArrayVel,): lambda j: (setattr(j._q, "_d", [0.0] * len(j._q._d)),
                               setattr(j._qdot, "_d", [0.0] * len(j._qdot._d))),
    (JntSpaceInertiaMatrix,): lambda m: setattr(m, "_r", [[0.0] * len(r) for r in m._r]),
}


def SetToZero(*args: Any) -> None:  # noqa: N802
    """Set an object's numbers to zero in place. (With three arguments ``(jac, frame,
    dest)`` it is, as in PyKDL, changeRefFrame: ``dest`` becomes ``jac`` transformed by
    ``frame``.)"""
    if len(args) == 3:
        src, frame, dest = args
        if isinstance(src, Jacobian) and isinstance(frame, Frame) and isinstance(dest, Jacobian):
            if len(src._c) == len(dest._c):
                dest._c = [_col_frame(c, frame) for c in src._c]
            return
    if len(args) != 1:
        raise TypeError("SetToZero() takes one object (or a Jacobian, a Frame and a Jacobian)")
    _dispatch("SetToZero", _SET_TO_ZERO, args)(args[0])


# ------------------------------------------------------------------ joint-space arithmetic

def _same_size(a: Sequence[float], b: Sequence[float], what: str) -> None:
    if len(a) != len(b):
        raise ValueError(f"{what}: the arrays have different sizes ({len(a)} and {len(b)})")


def _factor(value: Any) -> float:
    try:
        return float(value)
    except (TypeError, ValueError):
        raise TypeError(f"expected a number, got {type(value).__name__}") from None


def Add(src1: Any, src2: Any, dest: Any) -> None:  # noqa: N802
    """dest = src1 + src2 (JntArray, JntArrayVel with a JntArrayVel or a JntArray, or
    JntSpaceInertiaMatrix)."""
    if isinstance(src1, JntArrayVel) and isinstance(dest, JntArrayVel):
        if isinstance(src2, JntArrayVel):
            Add(src1._q, src2._q, dest._q)
            Add(src1._qdot, src2._qdot, dest._qdot)
        elif isinstance(src2, JntArray):
            Add(src1._q, src2, dest._q)
            dest._qdot._d = src1._qdot._d[:]
        else:
            raise TypeError(f"Add(JntArrayVel, ?, JntArrayVel): got {type(src2).__name__}")
        return
    if isinstance(src1, JntArray) and isinstance(src2, JntArray) and isinstance(dest, JntArray):
        _same_size(src1._d, src2._d, "Add")
        dest._d = [a + b for a, b in zip(src1._d, src2._d)]
        return
    if all(isinstance(x, JntSpaceInertiaMatrix) for x in (src1, src2, dest)):
        _same_size(src1._r, src2._r, "Add")
        dest._r = [[a + b for a, b in zip(r, s)] for r, s in zip(src1._r, src2._r)]
        return
    raise TypeError("Add() takes (JntArray, JntArray, JntArray), (JntArrayVel, JntArrayVel or "
                    "JntArray, JntArrayVel) or three JntSpaceInertiaMatrix")


def Subtract(src1: Any, src2: Any, dest: Any) -> None:  # noqa: N802
    """dest = src1 - src2 (the same kinds as Add)."""
    if isinstance(src1, JntArrayVel) and isinstance(dest, JntArrayVel):
        if isinstance(src2, JntArrayVel):
            Subtract(src1._q, src2._q, dest._q)
            Subtract(src1._qdot, src2._qdot, dest._qdot)
        elif isinstance(src2, JntArray):
            Subtract(src1._q, src2, dest._q)
            dest._qdot._d = src1._qdot._d[:]
        else:
            raise TypeError(f"Subtract(JntArrayVel, ?, JntArrayVel): got {type(src2).__name__}")
        return
    if isinstance(src1, JntArray) and isinstance(src2, JntArray) and isinstance(dest, JntArray):
        _same_size(src1._d, src2._d, "Subtract")
        dest._d = [a - b for a, b in zip(src1._d, src2._d)]
        return
    if all(isinstance(x, JntSpaceInertiaMatrix) for x in (src1, src2, dest)):
        _same_size(src1._r, src2._r, "Subtract")
        dest._r = [[a - b for a, b in zip(r, s)] for r, s in zip(src1._r, src2._r)]
        return
    raise TypeError("Subtract() takes (JntArray, JntArray, JntArray), (JntArrayVel, JntArrayVel "
                    "or JntArray, JntArrayVel) or three JntSpaceInertiaMatrix")


def Multiply(src: Any, factor: Any, dest: Any) -> None:  # noqa: N802
    """dest = factor * src (JntArray, JntArrayVel by a number or a doubleVel,
    JntSpaceInertiaMatrix by a number), or dest = src * factor for a JntSpaceInertiaMatrix and
    a JntArray."""
    if isinstance(src, JntArrayVel) and isinstance(dest, JntArrayVel):
        q, qdot = src._q._d[:], src._qdot._d[:]
        if isinstance(factor, doubleVel):
            t, g = factor.t, factor.grad
            dest._q._d = [t * a for a in q]
            dest._qdot._d = [t * b + g * a for a, b in zip(q, qdot)]
        else:
            s = _factor(factor)
            dest._q._d, dest._qdot._d = [s * a for a in q], [s * b for b in qdot]
        return
    if isinstance(src, JntArray) and isinstance(dest, JntArray):
        s = _factor(factor)
        dest._d = [s * a for a in src._d]
        return
    if isinstance(src, JntSpaceInertiaMatrix) and isinstance(factor, JntArray) \
            and isinstance(dest, JntArray):
        _same_size(src._r, factor._d, "Multiply")
        dest._d = [sum(a * b for a, b in zip(row, factor._d)) for row in src._r]
        return
    if isinstance(src, JntSpaceInertiaMatrix) and isinstance(dest, JntSpaceInertiaMatrix):
        s = _factor(factor)
        dest._r = [[s * a for a in row] for row in src._r]
        return
    raise TypeError("Multiply() takes (JntArray, number, JntArray), (JntArrayVel, number or "
                    "doubleVel, JntArrayVel), (JntSpaceInertiaMatrix, number, "
                    "JntSpaceInertiaMatrix) or (JntSpaceInertiaMatrix, JntArray, JntArray)")


def Divide(src: Any, factor: Any, dest: Any) -> None:  # noqa: N802
    """dest = src / factor (JntArray, JntArrayVel by a number or a doubleVel,
    JntSpaceInertiaMatrix)."""
    if isinstance(src, JntArrayVel) and isinstance(dest, JntArrayVel):
        q, qdot = src._q._d[:], src._qdot._d[:]
        if isinstance(factor, doubleVel):
            t, g = factor.t, factor.grad
            k = g / t / t
            dest._q._d = _divide(q, t)
            dest._qdot._d = [b - k * a for a, b in zip(q, _divide(qdot, t))]
        else:
            s = _factor(factor)
            dest._q._d, dest._qdot._d = _divide(q, s), _divide(qdot, s)
        return
    if isinstance(src, JntArray) and isinstance(dest, JntArray):
        dest._d = _divide(src._d, _factor(factor))
        return
    if isinstance(src, JntSpaceInertiaMatrix) and isinstance(dest, JntSpaceInertiaMatrix):
        s = _factor(factor)
        dest._r = [_divide(row, s) for row in src._r]
        return
    raise TypeError("Divide() takes (JntArray, number, JntArray), (JntArrayVel, number or "
                    "doubleVel, JntArrayVel) or (JntSpaceInertiaMatrix, number, "
                    "JntSpaceInertiaMatrix)")


def MultiplyJacobian(jac: Jacobian, src: JntArray, dest: Twist) -> None:  # noqa: N802
    """dest = jac * src: the end effector's twist for joint velocities ``src``."""
    if not (isinstance(jac, Jacobian) and isinstance(src, JntArray) and isinstance(dest, Twist)):
        raise TypeError("MultiplyJacobian() takes (Jacobian, JntArray, Twist)")
    _same_size(jac._c, src._d, "MultiplyJacobian")
    out = [0.0] * 6
    for column, qd in zip(jac._c, src._d):
        for i in range(6):
            out[i] += column[i] * qd
    dest._vel._d, dest._rot._d = out[:3], out[3:]


def changeRefPoint(src: Jacobian, base_AB: Vector, dest: Jacobian) -> None:  # noqa: N802, N803
    """dest = src with every column referred to point ``base_AB`` (dest must have as many
    columns as src; otherwise nothing changes, as in KDL)."""
    if len(src._c) == len(dest._c):
        dest._c = [_col_refpoint(c, base_AB._d) for c in src._c]


def changeBase(src: Jacobian, rot: Rotation, dest: Jacobian) -> None:  # noqa: N802
    """dest = src with every column rotated by ``rot`` (same columns, as changeRefPoint)."""
    if len(src._c) == len(dest._c):
        dest._c = [_col_rotate(c, rot._d) for c in src._c]
