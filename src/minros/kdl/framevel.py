"""PyKDL's first-order automatic differentiation: doubleVel, VectorVel, RotationVel, FrameVel
and TwistVel, each a value with its time derivative (what ChainFkSolverVel_recursive returns).

A RotationVel's derivative is the angular velocity ``w`` in the base frame, so the derivative of
``R v`` is ``w x (R v) + R v'``; a FrameVel is (RotationVel ``M``, VectorVel ``p``). The
operators are KDL's, including two of its slips, kept so that the numbers stay Debian's:
``RotationVel.RotY`` builds its matrix about x, and ``diff(FrameVel, FrameVel)`` returns a
TwistVel whose ``vel`` holds the rotation's difference and ``rot`` the position's.
"""

from __future__ import annotations

from typing import Any, List, Sequence, Tuple

from .frames import (
    EPSILON,
    Frame,
    Rotation,
    Twist,
    Vector,
    _close,
    _cross,
    _divide,
    _normalized,
    _rot2,
    _rot_mul,
    _rot_rot,
    _rot_tmul,
    _rotation,
    _scale_of,
    _transpose,
    _vector,
)

__all__ = ["doubleVel", "VectorVel", "RotationVel", "FrameVel", "TwistVel"]

_new = object.__new__
_ZERO3 = (0.0, 0.0, 0.0)


def _add(a: Sequence[float], b: Sequence[float]) -> List[float]:
    return [a[0] + b[0], a[1] + b[1], a[2] + b[2]]


def _sub(a: Sequence[float], b: Sequence[float]) -> List[float]:
    return [a[0] - b[0], a[1] - b[1], a[2] - b[2]]


def _scale(s: float, a: Sequence[float]) -> List[float]:
    return [s * a[0], s * a[1], s * a[2]]


def _dot(a: Sequence[float], b: Sequence[float]) -> float:
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]


def _g(value: float) -> str:
    """A number as C++'s default stream prints it."""
    return f"{value:g}"


class doubleVel:  # noqa: N801 (PyKDL's name)
    """A number ``t`` with its derivative ``grad``: ``doubleVel()``, ``doubleVel(t)``,
    ``doubleVel(t, grad)`` or ``doubleVel(other)``."""

    __slots__ = ("t", "grad")

    def __init__(self, t: Any = 0.0, grad: Any = None) -> None:
        if isinstance(t, doubleVel) and grad is None:
            self.t, self.grad = t.t, t.grad
            return
        try:
            self.t, self.grad = float(t), 0.0 if grad is None else float(grad)
        except (TypeError, ValueError):
            raise TypeError("doubleVel() takes no arguments, a number t, numbers (t, grad) "
                            f"or a doubleVel; got {t!r}, {grad!r}") from None

    def value(self) -> float:
        return self.t

    def deriv(self) -> float:
        return self.grad

    def __repr__(self) -> str:
        return f"Rall1d<d, d, d>({_g(self.t)},{_g(self.grad)})"

    def __neg__(self) -> doubleVel:
        return _dv(-self.t, -self.grad)

    def __eq__(self, other: Any) -> Any:
        if not isinstance(other, doubleVel):
            return NotImplemented
        return _close((self.t, self.grad), (other.t, other.grad), EPSILON)

    def __ne__(self, other: Any) -> Any:
        if not isinstance(other, doubleVel):
            return NotImplemented
        return not self.__eq__(other)

    def __copy__(self) -> doubleVel:
        return _dv(self.t, self.grad)

    def __deepcopy__(self, memo: Any) -> doubleVel:
        return _dv(self.t, self.grad)

    def __getstate__(self) -> Tuple[float, float]:
        return (self.t, self.grad)

    def __setstate__(self, state: Sequence[float]) -> None:
        self.t, self.grad = float(state[0]), float(state[1])

    def __reduce__(self) -> Any:
        return (doubleVel, (self.t, self.grad))


def _dv(t: float, grad: float) -> doubleVel:
    d = _new(doubleVel)
    d.t, d.grad = t, grad
    return d


def _as_dv(value: Any) -> doubleVel:
    if isinstance(value, doubleVel):
        return value
    s = _scale_of(value)
    if s is None:
        raise TypeError(f"expected a doubleVel or a number, got {type(value).__name__}")
    return _dv(s, 0.0)


def _vector_arg(value: Any, what: str) -> Vector:
    if not isinstance(value, Vector):
        raise TypeError(f"{what} must be a Vector, got {type(value).__name__}")
    return value


class VectorVel:
    """A Vector ``p`` with its derivative ``v``: ``VectorVel()``, ``VectorVel(p)``,
    ``VectorVel(p, v)`` or ``VectorVel(other)``."""

    __slots__ = ("_p", "_v")

    def __init__(self, p: Any = None, v: Any = None) -> None:
        if isinstance(p, VectorVel) and v is None:
            self._p, self._v = _vector(*p._p._d), _vector(*p._v._d)
            return
        self._p = _vector(*_vector_arg(p, "VectorVel's p")._d) if p is not None else _vector(*_ZERO3)
        self._v = _vector(*_vector_arg(v, "VectorVel's v")._d) if v is not None else _vector(*_ZERO3)

    p = property(lambda self: self._p, lambda self, value: _assign(self._p, value, "VectorVel.p"),
                 doc="The value (the object's own Vector).")
    v = property(lambda self: self._v, lambda self, value: _assign(self._v, value, "VectorVel.v"),
                 doc="The derivative (the object's own Vector).")

    def value(self) -> Vector:
        return _vector(*self._p._d)

    def deriv(self) -> Vector:
        return _vector(*self._v._d)

    def __repr__(self) -> str:
        return f"{{{self._p!r},{self._v!r}}}\n"

    @staticmethod
    def Zero() -> VectorVel:  # noqa: N802
        return _vv(list(_ZERO3), list(_ZERO3))

    def ReverseSign(self) -> None:  # noqa: N802
        self._p.ReverseSign()
        self._v.ReverseSign()

    def Norm(self, eps: float = EPSILON) -> doubleVel:  # noqa: N802
        """The length and its derivative (both 0 when p is shorter than ``eps``)."""
        n = self._p.Norm(eps)
        if n < eps:
            return _dv(0.0, 0.0)
        return _dv(n, _dot(self._p._d, self._v._d) / n)

    def __add__(self, other: Any) -> Any:
        if isinstance(other, VectorVel):
            return _vv(_add(self._p._d, other._p._d), _add(self._v._d, other._v._d))
        if isinstance(other, Vector):
            return _vv(_add(self._p._d, other._d), self._v._d[:])
        return NotImplemented

    def __radd__(self, other: Any) -> Any:
        if isinstance(other, Vector):
            return _vv(_add(other._d, self._p._d), self._v._d[:])
        return NotImplemented

    def __sub__(self, other: Any) -> Any:
        if isinstance(other, VectorVel):
            return _vv(_sub(self._p._d, other._p._d), _sub(self._v._d, other._v._d))
        if isinstance(other, Vector):
            return _vv(_sub(self._p._d, other._d), self._v._d[:])
        return NotImplemented

    def __rsub__(self, other: Any) -> Any:
        if isinstance(other, Vector):
            return _vv(_sub(other._d, self._p._d), _scale(-1.0, self._v._d))
        return NotImplemented

    def __iadd__(self, other: Any) -> Any:
        if not isinstance(other, VectorVel):
            return NotImplemented
        self._p._d = _add(self._p._d, other._p._d)
        self._v._d = _add(self._v._d, other._v._d)
        return self

    def __isub__(self, other: Any) -> Any:
        if not isinstance(other, VectorVel):
            return NotImplemented
        self._p._d = _sub(self._p._d, other._p._d)
        self._v._d = _sub(self._v._d, other._v._d)
        return self

    def __mul__(self, other: Any) -> Any:
        p, v = self._p._d, self._v._d
        if isinstance(other, VectorVel):
            q, w = other._p._d, other._v._d
            return _vv(_cross(p, q), _add(_cross(p, w), _cross(v, q)))
        if isinstance(other, Vector):
            return _vv(_cross(p, other._d), _cross(v, other._d))
        if isinstance(other, doubleVel):
            return _vv(_scale(other.t, p), _add(_scale(other.t, v), _scale(other.grad, p)))
        s = _scale_of(other)
        if s is None:
            return NotImplemented
        return _vv([x * s for x in p], [x * s for x in v])

    def __rmul__(self, other: Any) -> Any:
        p, v = self._p._d, self._v._d
        if isinstance(other, Vector):
            return _vv(_cross(other._d, p), _cross(other._d, v))
        if isinstance(other, Rotation):
            return _vv(_rot_mul(other._d, p), _rot_mul(other._d, v))
        if isinstance(other, doubleVel):
            return _vv(_scale(other.t, p), _add(_scale(other.t, v), _scale(other.grad, p)))
        s = _scale_of(other)
        if s is None:
            return NotImplemented
        return _vv(_scale(s, p), _scale(s, v))

    def __truediv__(self, other: Any) -> Any:
        p, v = self._p._d, self._v._d
        if isinstance(other, doubleVel):
            t, g = other.t, other.grad
            return _vv(_divide(p, t), _sub(_divide(v, t), _divide(_divide(_scale(g, p), t), t)))
        s = _scale_of(other)
        if s is None:
            return NotImplemented
        return _vv(_divide(p, s), _divide(v, s))

    def __neg__(self) -> VectorVel:
        return _vv(_scale(-1.0, self._p._d), _scale(-1.0, self._v._d))

    def __eq__(self, other: Any) -> Any:
        if isinstance(other, VectorVel):
            return _close(self._p._d, other._p._d, EPSILON) and _close(self._v._d, other._v._d, EPSILON)
        if isinstance(other, Vector):
            return _close(self._p._d, other._d, EPSILON) and _close(self._v._d, _ZERO3, EPSILON)
        return NotImplemented

    def __ne__(self, other: Any) -> Any:
        same = self.__eq__(other)
        return same if same is NotImplemented else not same

    def __copy__(self) -> VectorVel:
        return _vv(self._p._d[:], self._v._d[:])

    def __deepcopy__(self, memo: Any) -> VectorVel:
        return self.__copy__()

    def __getstate__(self) -> Tuple[Vector, Vector]:
        return (self.value(), self.deriv())

    def __setstate__(self, state: Sequence[Any]) -> None:
        self._p, self._v = _vector(*state[0]._d), _vector(*state[1]._d)

    def __reduce__(self) -> Any:
        return (VectorVel, self.__getstate__())


def _assign(target: Any, value: Any, what: str) -> None:
    """``obj.member = value`` copies value's numbers into the member, as PyKDL's readwrite
    members do."""
    if not isinstance(value, type(target)):
        raise TypeError(f"{what} must be a {type(target).__name__}, got {type(value).__name__}")
    _copy_into(target, value)


def _copy_into(target: Any, value: Any) -> None:
    if isinstance(target, (Vector, Rotation)):
        target._d = value._d[:]
    elif isinstance(target, VectorVel):
        target._p._d, target._v._d = value._p._d[:], value._v._d[:]
    elif isinstance(target, RotationVel):
        target._R._d, target._w._d = value._R._d[:], value._w._d[:]


def _vv(p: List[float], v: List[float]) -> VectorVel:
    r = _new(VectorVel)
    r._p, r._v = _vector(*p), _vector(*v)
    return r


def _rv(m: List[float], w: List[float]) -> RotationVel:
    r = _new(RotationVel)
    r._R, r._w = _rotation(m), _vector(*w)
    return r


class RotationVel:
    """A Rotation ``R`` with its angular velocity ``w`` (in the base frame):
    ``RotationVel()``, ``RotationVel(R)``, ``RotationVel(R, w)`` or ``RotationVel(other)``."""

    __slots__ = ("_R", "_w")

    def __init__(self, R: Any = None, w: Any = None) -> None:  # noqa: N803
        if isinstance(R, RotationVel) and w is None:
            self._R, self._w = _rotation(R._R._d[:]), _vector(*R._w._d)
            return
        if R is not None and not isinstance(R, Rotation):
            raise TypeError(f"RotationVel's R must be a Rotation, got {type(R).__name__}")
        self._R = _rotation(R._d[:]) if R is not None else Rotation.Identity()
        self._w = _vector(*_vector_arg(w, "RotationVel's w")._d) if w is not None else _vector(*_ZERO3)

    R = property(lambda self: self._R, lambda self, value: _assign(self._R, value, "RotationVel.R"),
                 doc="The rotation (the object's own Rotation).")
    w = property(lambda self: self._w, lambda self, value: _assign(self._w, value, "RotationVel.w"),
                 doc="The angular velocity (the object's own Vector).")

    def value(self) -> Rotation:
        return _rotation(self._R._d[:])

    def deriv(self) -> Vector:
        return _vector(*self._w._d)

    def __repr__(self) -> str:
        return f"{{\n{self._R!r},\n{self._w!r}\n}}\n"

    def _unit(self, j: int) -> VectorVel:
        d = self._R._d
        u = [d[j], d[j + 3], d[j + 6]]
        return _vv(u, _cross(self._w._d, u))

    def UnitX(self) -> VectorVel:  # noqa: N802
        return self._unit(0)

    def UnitY(self) -> VectorVel:  # noqa: N802
        return self._unit(1)

    def UnitZ(self) -> VectorVel:  # noqa: N802
        return self._unit(2)

    @staticmethod
    def Identity() -> RotationVel:  # noqa: N802
        return _rv([1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0], list(_ZERO3))

    def Inverse(self, arg: Any = None) -> Any:  # noqa: N802
        """The inverse; ``Inverse(x)`` applies it to a VectorVel, Vector, TwistVel or Twist."""
        m, w = self._R._d, self._w._d
        if arg is None:
            return _rv(_transpose(m), _scale(-1.0, _rot_tmul(m, w)))
        if isinstance(arg, VectorVel):
            p = arg._p._d
            return _vv(_rot_tmul(m, p), _rot_tmul(m, _sub(arg._v._d, _cross(w, p))))
        if isinstance(arg, Vector):
            return _vv(_rot_tmul(m, arg._d), _rot_tmul(m, _cross(_scale(-1.0, w), arg._d)))
        if isinstance(arg, TwistVel):
            return _tv(self.Inverse(arg._vel), self.Inverse(arg._rot))
        if isinstance(arg, Twist):
            return _tv(self.Inverse(arg._vel), self.Inverse(arg._rot))
        raise TypeError("RotationVel.Inverse() takes nothing, a VectorVel, a Vector, a "
                        f"TwistVel or a Twist; got {type(arg).__name__}")

    def _do_rot(self, angle: Any, axis: int, method: str) -> None:
        a = _as_dv(angle)
        e = [0.0, 0.0, 0.0]
        e[axis] = a.grad
        self._w._d = _add(self._w._d, _rot_mul(self._R._d, e))
        getattr(self._R, method)(a.t)

    def DoRotX(self, angle: Any) -> None:  # noqa: N802
        self._do_rot(angle, 0, "DoRotX")

    def DoRotY(self, angle: Any) -> None:  # noqa: N802
        self._do_rot(angle, 1, "DoRotY")

    def DoRotZ(self, angle: Any) -> None:  # noqa: N802
        self._do_rot(angle, 2, "DoRotZ")

    @staticmethod
    def RotX(angle: Any) -> RotationVel:  # noqa: N802
        a = _as_dv(angle)
        return _rv(Rotation.RotX(a.t)._d, [a.grad, 0.0, 0.0])

    @staticmethod
    def RotY(angle: Any) -> RotationVel:  # noqa: N802
        """As KDL 1.5.1: the matrix is a rotation about x (see the module's note)."""
        a = _as_dv(angle)
        return _rv(Rotation.RotX(a.t)._d, [0.0, a.grad, 0.0])

    @staticmethod
    def RotZ(angle: Any) -> RotationVel:  # noqa: N802
        a = _as_dv(angle)
        return _rv(Rotation.RotZ(a.t)._d, [0.0, 0.0, a.grad])

    @staticmethod
    def Rot(rotvec: Vector, angle: Any) -> RotationVel:  # noqa: N802
        a = _as_dv(angle)
        axis, _ = _normalized(*rotvec._d)
        return _rv(_rot2(axis, a.t), _scale(a.grad, axis))

    @staticmethod
    def Rot2(rotvec: Vector, angle: Any) -> RotationVel:  # noqa: N802
        a = _as_dv(angle)
        return _rv(_rot2(rotvec._d, a.t), [x * a.grad for x in rotvec._d])

    def __mul__(self, other: Any) -> Any:
        m, w = self._R._d, self._w._d
        if isinstance(other, VectorVel):
            tmp = _rot_mul(m, other._p._d)
            return _vv(tmp, _add(_cross(w, tmp), _rot_mul(m, other._v._d)))
        if isinstance(other, Vector):
            tmp = _rot_mul(m, other._d)
            return _vv(tmp, _cross(w, tmp))
        if isinstance(other, (TwistVel, Twist)):
            return _tv(self * other._vel, self * other._rot)
        if isinstance(other, RotationVel):
            return _rv(_rot_rot(m, other._R._d), _add(w, _rot_mul(m, other._w._d)))
        if isinstance(other, Rotation):
            return _rv(_rot_rot(m, other._d), w[:])
        return NotImplemented

    def __rmul__(self, other: Any) -> Any:
        if isinstance(other, Rotation):
            return _rv(_rot_rot(other._d, self._R._d), _rot_mul(other._d, self._w._d))
        return NotImplemented

    def __eq__(self, other: Any) -> Any:
        if isinstance(other, RotationVel):
            return _close(self._w._d, other._w._d, EPSILON) and _close(self._R._d, other._R._d, EPSILON)
        if isinstance(other, Rotation):
            return _close(self._w._d, _ZERO3, EPSILON) and _close(self._R._d, other._d, EPSILON)
        return NotImplemented

    def __ne__(self, other: Any) -> Any:
        same = self.__eq__(other)
        return same if same is NotImplemented else not same

    def __copy__(self) -> RotationVel:
        return _rv(self._R._d[:], self._w._d[:])

    def __deepcopy__(self, memo: Any) -> RotationVel:
        return self.__copy__()

    def __getstate__(self) -> Tuple[Rotation, Vector]:
        return (self.value(), self.deriv())

    def __setstate__(self, state: Sequence[Any]) -> None:
        self._R, self._w = _rotation(state[0]._d[:]), _vector(*state[1]._d)

    def __reduce__(self) -> Any:
        return (RotationVel, self.__getstate__())


def _tv(vel: VectorVel, rot: VectorVel) -> TwistVel:
    t = _new(TwistVel)
    t._vel, t._rot = vel, rot
    return t


def _fv(m: RotationVel, p: VectorVel) -> FrameVel:
    f = _new(FrameVel)
    f._M, f._p = m, p
    return f


class FrameVel:
    """A Frame with its Twist: RotationVel ``M`` and VectorVel ``p``. ``FrameVel()``,
    ``FrameVel(T)``, ``FrameVel(T, t)`` (Frame and Twist), ``FrameVel(M, p)`` or
    ``FrameVel(other)``."""

    __slots__ = ("_M", "_p")

    def __init__(self, *args: Any, **kwargs: Any) -> None:
        for name in ("T", "t", "M", "p"):
            if name in kwargs:
                args = args + (kwargs.pop(name),)
        if kwargs:
            raise TypeError(f"FrameVel() got unexpected keyword arguments {sorted(kwargs)}")
        n = len(args)
        if n == 0:
            self._M, self._p = RotationVel.Identity(), VectorVel.Zero()
        elif n == 1 and isinstance(args[0], FrameVel):
            self._M, self._p = args[0]._M.__copy__(), args[0]._p.__copy__()
        elif n in (1, 2) and isinstance(args[0], Frame):
            twist = args[1] if n == 2 else Twist()
            if not isinstance(twist, Twist):
                raise TypeError(f"FrameVel(T, t): t must be a Twist, got {type(twist).__name__}")
            f = args[0]
            self._M = _rv(f._M._d[:], twist._rot._d[:])
            self._p = _vv(f._p._d[:], twist._vel._d[:])
        elif n == 2 and isinstance(args[0], RotationVel) and isinstance(args[1], VectorVel):
            self._M, self._p = args[0].__copy__(), args[1].__copy__()
        else:
            raise TypeError("FrameVel() takes no arguments, a Frame, (Frame, Twist), "
                            f"(RotationVel, VectorVel) or a FrameVel; got {args!r}")

    M = property(lambda self: self._M, lambda self, value: _assign(self._M, value, "FrameVel.M"),
                 doc="The RotationVel (the object's own).")
    p = property(lambda self: self._p, lambda self, value: _assign(self._p, value, "FrameVel.p"),
                 doc="The VectorVel (the object's own).")

    def value(self) -> Frame:
        return Frame(self._M._R, self._p._p)

    def deriv(self) -> Twist:
        return Twist(self._p._v, self._M._w)

    GetFrame = value
    GetTwist = deriv

    def __repr__(self) -> str:
        return f"{{\n{self._M!r},\n{self._p!r}\n}}\n"

    @staticmethod
    def Identity() -> FrameVel:  # noqa: N802
        return _fv(RotationVel.Identity(), VectorVel.Zero())

    def Inverse(self, arg: Any = None) -> Any:  # noqa: N802
        """The inverse; ``Inverse(x)`` applies it to a VectorVel, Vector, TwistVel or Twist."""
        M, p = self._M, self._p  # noqa: N806
        if arg is None:
            return _fv(M.Inverse(), -M.Inverse(p))
        if isinstance(arg, (VectorVel, Vector)):
            return M.Inverse(arg - p)
        if isinstance(arg, (TwistVel, Twist)):
            return _tv(M.Inverse(arg._vel - p * arg._rot), M.Inverse(arg._rot))
        raise TypeError("FrameVel.Inverse() takes nothing, a VectorVel, a Vector, a TwistVel "
                        f"or a Twist; got {type(arg).__name__}")

    def __mul__(self, other: Any) -> Any:
        M, p = self._M, self._p  # noqa: N806
        if isinstance(other, (VectorVel, Vector)):
            return M * other + p
        if isinstance(other, (TwistVel, Twist)):
            rot = M * other._rot
            return _tv(M * other._vel + p * rot, rot)
        if isinstance(other, FrameVel):
            return _fv(M * other._M, M * other._p + p)
        if isinstance(other, Frame):
            return _fv(M * other._M, M * other._p + p)
        return NotImplemented

    def __rmul__(self, other: Any) -> Any:
        if isinstance(other, Frame):
            return _fv(other._M * self._M, other._M * self._p + other._p)
        return NotImplemented

    def __eq__(self, other: Any) -> Any:
        if isinstance(other, (FrameVel, Frame)):
            return self._M == other._M and self._p == other._p
        return NotImplemented

    def __ne__(self, other: Any) -> Any:
        same = self.__eq__(other)
        return same if same is NotImplemented else not same

    def __copy__(self) -> FrameVel:
        return _fv(self._M.__copy__(), self._p.__copy__())

    def __deepcopy__(self, memo: Any) -> FrameVel:
        return self.__copy__()

    def __getstate__(self) -> Tuple[RotationVel, VectorVel]:
        return (self._M.__copy__(), self._p.__copy__())

    def __setstate__(self, state: Sequence[Any]) -> None:
        self._M, self._p = state[0].__copy__(), state[1].__copy__()

    def __reduce__(self) -> Any:
        return (FrameVel, self.__getstate__())


class TwistVel:
    """A Twist with its derivative: VectorVels ``vel`` and ``rot``. ``TwistVel()``,
    ``TwistVel(vel, rot)`` (VectorVels), ``TwistVel(p, v)`` (a Twist and its derivative),
    ``TwistVel(p)`` or ``TwistVel(other)``."""

    __slots__ = ("_vel", "_rot")

    def __init__(self, *args: Any, **kwargs: Any) -> None:
        for name in ("vel", "rot", "p", "v"):
            if name in kwargs:
                args = args + (kwargs.pop(name),)
        if kwargs:
            raise TypeError(f"TwistVel() got unexpected keyword arguments {sorted(kwargs)}")
        n = len(args)
        if n == 0:
            self._vel, self._rot = VectorVel.Zero(), VectorVel.Zero()
        elif n == 1 and isinstance(args[0], TwistVel):
            self._vel, self._rot = args[0]._vel.__copy__(), args[0]._rot.__copy__()
        elif n == 2 and isinstance(args[0], VectorVel) and isinstance(args[1], VectorVel):
            self._vel, self._rot = args[0].__copy__(), args[1].__copy__()
        elif n in (1, 2) and isinstance(args[0], Twist):
            d = args[1] if n == 2 else Twist()
            if not isinstance(d, Twist):
                raise TypeError(f"TwistVel(p, v): v must be a Twist, got {type(d).__name__}")
            self._vel = _vv(args[0]._vel._d[:], d._vel._d[:])
            self._rot = _vv(args[0]._rot._d[:], d._rot._d[:])
        else:
            raise TypeError("TwistVel() takes no arguments, (VectorVel, VectorVel), a Twist, "
                            f"(Twist, Twist) or a TwistVel; got {args!r}")

    vel = property(lambda self: self._vel,
                   lambda self, value: _assign(self._vel, value, "TwistVel.vel"),
                   doc="The linear part (the object's own VectorVel).")
    rot = property(lambda self: self._rot,
                   lambda self, value: _assign(self._rot, value, "TwistVel.rot"),
                   doc="The angular part (the object's own VectorVel).")

    def value(self) -> Twist:
        return Twist(self._vel._p, self._rot._p)

    def deriv(self) -> Twist:
        return Twist(self._vel._v, self._rot._v)

    GetTwist = value
    GetTwistDot = deriv

    def __repr__(self) -> str:
        return f"{{\n{self._vel!r},\n{self._rot!r}\n}}\n"

    @staticmethod
    def Zero() -> TwistVel:  # noqa: N802
        return _tv(VectorVel.Zero(), VectorVel.Zero())

    def ReverseSign(self) -> None:  # noqa: N802
        self._vel.ReverseSign()
        self._rot.ReverseSign()

    def RefPoint(self, base: VectorVel) -> TwistVel:  # noqa: N802
        return _tv(self._vel + self._rot * base, self._rot.__copy__())

    def __iadd__(self, other: Any) -> Any:
        if not isinstance(other, TwistVel):
            return NotImplemented
        self._vel += other._vel
        self._rot += other._rot
        return self

    def __isub__(self, other: Any) -> Any:
        if not isinstance(other, TwistVel):
            return NotImplemented
        self._vel -= other._vel
        self._rot -= other._rot
        return self

    def __add__(self, other: Any) -> Any:
        if not isinstance(other, TwistVel):
            return NotImplemented
        return _tv(self._vel + other._vel, self._rot + other._rot)

    def __sub__(self, other: Any) -> Any:
        if not isinstance(other, TwistVel):
            return NotImplemented
        return _tv(self._vel - other._vel, self._rot - other._rot)

    def __mul__(self, other: Any) -> Any:
        if isinstance(other, doubleVel) or _scale_of(other) is not None:
            return _tv(self._vel * other, self._rot * other)
        return NotImplemented

    __rmul__ = __mul__

    def __truediv__(self, other: Any) -> Any:
        if isinstance(other, doubleVel) or _scale_of(other) is not None:
            return _tv(self._vel / other, self._rot / other)
        return NotImplemented

    def __neg__(self) -> TwistVel:
        return _tv(-self._vel, -self._rot)

    def __eq__(self, other: Any) -> Any:
        if isinstance(other, TwistVel):
            return self._rot == other._rot and self._vel == other._vel
        if isinstance(other, Twist):
            return self._rot == other._rot and self._vel == other._vel
        return NotImplemented

    def __ne__(self, other: Any) -> Any:
        same = self.__eq__(other)
        return same if same is NotImplemented else not same

    def __copy__(self) -> TwistVel:
        return _tv(self._vel.__copy__(), self._rot.__copy__())

    def __deepcopy__(self, memo: Any) -> TwistVel:
        return self.__copy__()

    def __getstate__(self) -> Tuple[VectorVel, VectorVel]:
        return (self._vel.__copy__(), self._rot.__copy__())

    def __setstate__(self, state: Sequence[Any]) -> None:
        self._vel, self._rot = state[0].__copy__(), state[1].__copy__()

    def __reduce__(self) -> Any:
        return (TwistVel, self.__getstate__())

