"""PyKDL's geometric primitives: Vector, Rotation, Frame, Twist and Wrench.

The conventions are Orocos KDL's (1.5.1, what Debian's python3-pykdl wraps): a Rotation is a
3x3 matrix kept row by row; ``Frame(R, p)`` maps a point ``v`` to ``R v + p``; a Twist is
(linear velocity ``vel``, angular velocity ``rot``) and a Wrench (``force``, ``torque``), both
referred to a point; ``==`` compares within KDL's epsilon (1e-6), as Debian's build does; the
Euler and quaternion conversions pick the same branches and signs as KDL's, so the numbers agree
with Debian's to the last bits.

Speed is the reason for the layout: every object keeps its numbers in one plain list ``_d``
(unpacked in one step by the operators), results are built with ``object.__new__`` without
running ``__init__``, and the operators test the exact class of their operand first. A Frame
holds its Rotation ``M`` and Vector ``p`` as objects, so ``frame.p[2] += 0.1`` changes the frame
(as in PyKDL, where ``M`` and ``p`` are references into the frame) while assigning
``frame.p = v`` copies ``v``'s numbers in (so ``v`` stays independent, as there).
"""

from __future__ import annotations

import math
from numbers import Real
from typing import Any, List, Sequence, Tuple

__all__ = ["Vector", "Rotation", "Frame", "Twist", "Wrench", "EPSILON"]

#: KDL's global epsilon: the default tolerance of ``==``, Equal, Norm and the solvers
EPSILON = 1e-6

_new = object.__new__
_sqrt, _sin, _cos, _atan2 = math.sqrt, math.sin, math.cos, math.atan2
_PI = math.pi
_HALF_PI = math.pi / 2.0
_INF, _NAN = math.inf, math.nan


def _fmt(x: float) -> str:
    """One number as KDL prints it (std::setw(12), six significant digits)."""
    return f"{x:12g}"


def _number(value: Any, what: str) -> float:
    """``value`` as a float; anything else is a TypeError naming ``what``."""
    if value.__class__ is float:
        return value
    if isinstance(value, Real):
        return float(value)
    raise TypeError(f"{what} must be a number, got {type(value).__name__} {value!r}")


def _scale_of(value: Any) -> Any:
    """The float of a scalar operand, or None when it is not a real number."""
    if value.__class__ is float:
        return value
    if isinstance(value, Real):
        return float(value)
    return None


def _ieee_div(x: float, y: float) -> float:
    """C's x / y (inf or nan where Python raises ZeroDivisionError)."""
    try:
        return x / y
    except ZeroDivisionError:
        if x != x or x == 0.0:
            return _NAN
        return math.copysign(_INF, x) * math.copysign(1.0, y)


def _divide(values: Sequence[float], y: float) -> List[float]:
    try:
        return [x / y for x in values]
    except ZeroDivisionError:
        return [_ieee_div(x, y) for x in values]


def _close(a: Sequence[float], b: Sequence[float], eps: float) -> bool:
    """KDL's Equal on each pair: a + eps > b and a - eps < b."""
    for x, y in zip(a, b):
        if not (x + eps > y and x - eps < y):
            return False
    return True


def _norm3(x: float, y: float, z: float, eps: float = EPSILON) -> float:
    """KDL's Vector::Norm: scaled by the largest component (no overflow), and 0 when every
    component is below ``eps``."""
    ax, ay = abs(x), abs(y)
    if ax >= ay:
        az = abs(z)
        if ax >= az:
            if ax < eps:
                return 0.0
            return ax * _sqrt(1 + (y / x) ** 2 + (z / x) ** 2)
        return az * _sqrt(1 + (x / z) ** 2 + (y / z) ** 2)
    az = abs(z)
    if ay > az:
        return ay * _sqrt(1 + (x / y) ** 2 + (z / y) ** 2)
    return az * _sqrt(1 + (x / z) ** 2 + (y / z) ** 2)


def _safe_sqrt(x: float) -> float:
    return _sqrt(x) if x >= 0.0 else _NAN


def _index(i: Any, size: int, name: str) -> int:
    """A Python int in range(size) (negative indices are out of range, as in PyKDL)."""
    try:
        i = i.__index__()
    except AttributeError:
        raise TypeError(f"{name} indices must be integers, got {type(i).__name__}") from None
    if i < 0 or i >= size:
        raise IndexError(f"{name} index out of range")
    return i


def _index2(idx: Any, rows: int, cols: int, name: str) -> int:
    """The flat row-major position of an ``[i, j]`` index."""
    try:
        i, j = idx
        i, j = i.__index__(), j.__index__()
    except (TypeError, ValueError, AttributeError):
        raise TypeError(f"{name} is indexed with two integers, as in m[i, j]; got {idx!r}") from None
    if i < 0 or i >= rows or j < 0 or j >= cols:
        raise IndexError(f"{name} index out of range")
    return i * cols + j


def _vector(x: float, y: float, z: float) -> Vector:
    v = _new(Vector)
    v._d = [x, y, z]
    return v


def _rotation(d: List[float]) -> Rotation:
    r = _new(Rotation)
    r._d = d
    return r


def _frame(m: List[float], p: List[float]) -> Frame:
    f = _new(Frame)
    r = _new(Rotation)
    r._d = m
    v = _new(Vector)
    v._d = p
    f._M = r
    f._p = v
    return f


def _twist(vel: List[float], rot: List[float]) -> Twist:
    t = _new(Twist)
    a = _new(Vector)
    a._d = vel
    b = _new(Vector)
    b._d = rot
    t._vel = a
    t._rot = b
    return t


def _wrench(force: List[float], torque: List[float]) -> Wrench:
    w = _new(Wrench)
    a = _new(Vector)
    a._d = force
    b = _new(Vector)
    b._d = torque
    w._force = a
    w._torque = b
    return w


def _cross(a: Sequence[float], b: Sequence[float]) -> List[float]:
    ax, ay, az = a
    bx, by, bz = b
    return [ay * bz - az * by, az * bx - ax * bz, ax * by - ay * bx]


def _rot_mul(m: Sequence[float], v: Sequence[float]) -> List[float]:
    a, b, c, d, e, f, g, h, i = m
    x, y, z = v
    return [a * x + b * y + c * z, d * x + e * y + f * z, g * x + h * y + i * z]


def _rot_tmul(m: Sequence[float], v: Sequence[float]) -> List[float]:
    """The transpose (inverse) of rotation ``m`` times ``v``."""
    a, b, c, d, e, f, g, h, i = m
    x, y, z = v
    return [a * x + d * y + g * z, b * x + e * y + h * z, c * x + f * y + i * z]


def _rot_rot(l: Sequence[float], r: Sequence[float]) -> List[float]:  # noqa: E741
    a, b, c, d, e, f, g, h, i = l
    A, B, C, D, E, F, G, H, I = r  # noqa: N806, E741
    return [a * A + b * D + c * G, a * B + b * E + c * H, a * C + b * F + c * I,
            d * A + e * D + f * G, d * B + e * E + f * H, d * C + e * F + f * I,
            g * A + h * D + i * G, g * B + h * E + i * H, g * C + h * F + i * I]


def _transpose(m: Sequence[float]) -> List[float]:
    return [m[0], m[3], m[6], m[1], m[4], m[7], m[2], m[5], m[8]]


def _rot2(axis: Sequence[float], angle: float) -> List[float]:
    """The rotation of ``angle`` about unit vector ``axis`` (KDL's Rot2, term by term)."""
    x, y, z = axis
    ct, st = _cos(angle), _sin(angle)
    vt = 1 - ct
    vx, vy, vz = vt * x, vt * y, vt * z
    sx, sy, sz = x * st, y * st, z * st
    vxy, vxz, vyz = vx * y, vx * z, vy * z
    return [ct + vx * x, -sz + vxy, sy + vxz,
            sz + vxy, ct + vy * y, -sx + vyz,
            -sy + vxz, sx + vyz, ct + vz * z]


def _normalized(x: float, y: float, z: float, eps: float = EPSILON) -> Tuple[List[float], float]:
    """KDL's Vector::Normalize: (unit vector, norm), or ((1, 0, 0), 0) below ``eps``."""
    n = _norm3(x, y, z)
    if n < eps:
        return [1.0, 0.0, 0.0], 0.0
    return _divide((x, y, z), n), n


def _rot_vector(x: float, y: float, z: float) -> List[float]:
    """KDL's Rot(axis_a_b): the rotation by |v| about v (a free function, used by addDelta)."""
    (ux, uy, uz), angle = _normalized(x, y, z, 1e-10)
    ct, st = _cos(angle), _sin(angle)
    vt = 1 - ct
    return [ct + vt * ux * ux, -uz * st + vt * ux * uy, uy * st + vt * ux * uz,
            uz * st + vt * uy * ux, ct + vt * uy * uy, -ux * st + vt * uy * uz,
            -uy * st + vt * uz * ux, ux * st + vt * uz * uy, ct + vt * uz * uz]


def _rot_angle(m: Sequence[float], eps: float = EPSILON) -> Tuple[float, List[float]]:
    """KDL's Rotation::GetRotAngle: (angle in [0, pi], unit axis); the identity gives axis
    (0, 0, 1); a half turn takes the axis from the symmetric part."""
    d0, d1, d2, d3, d4, d5, d6, d7, d8 = m
    eps2 = eps * 10
    if abs(d1 - d3) < eps and abs(d2 - d6) < eps and abs(d5 - d7) < eps:
        if (abs(d1 + d3) < eps2 and abs(d2 + d6) < eps2 and abs(d5 + d7) < eps2
                and abs(d0 + d4 + d8 - 3) < eps2):
            return 0.0, [0.0, 0.0, 1.0]
        xx, yy, zz = (d0 + 1) / 2, (d4 + 1) / 2, (d8 + 1) / 2
        xy, xz, yz = (d1 + d3) / 4, (d2 + d6) / 4, (d5 + d7) / 4
        if xx > yy and xx > zz:
            x = _safe_sqrt(xx)
            axis = [x, _ieee_div(xy, x), _ieee_div(xz, x)]
        elif yy > zz:
            y = _safe_sqrt(yy)
            axis = [_ieee_div(xy, y), y, _ieee_div(yz, y)]
        else:
            z = _safe_sqrt(zz)
            axis = [_ieee_div(xz, z), _ieee_div(yz, z), z]
        return _PI, axis
    f = (d0 + d4 + d8 - 1) / 2
    x, y, z = d7 - d5, d2 - d6, d3 - d1
    angle = _atan2(_norm3(x, y, z) / 2, f)
    axis, _ = _normalized(x, y, z)
    return angle, axis


class Vector:
    """A 3-vector: ``Vector()``, ``Vector(x, y, z)`` or ``Vector(other)`` (a copy).

    ``v * w`` is the cross product, ``v * 2.0`` a scaling; ``v[i]`` and ``v.x()`` read,
    ``v[i] = s`` and ``v.x(s)`` write."""

    __slots__ = ("_d", "header")

    def __init__(self, x: Any = None, y: Any = None, z: Any = None) -> None:
        if z is not None:
            try:
                self._d = [float(x), float(y), float(z)]
                return
            except (TypeError, ValueError):
                pass
        elif y is None:
            if x is None:
                self._d = [0.0, 0.0, 0.0]
                return
            if isinstance(x, Vector):
                self._d = x._d[:]
                return
        raise TypeError("Vector() takes no arguments, three numbers (x, y, z) or a Vector; "
                        f"got {', '.join(repr(a) for a in (x, y, z) if a is not None)}")

    # -- elements
    def x(self, value: Any = None) -> Any:
        """The x component; ``x(s)`` sets it."""
        if value is None:
            return self._d[0]
        self._d[0] = _number(value, "Vector.x")
        return None

    def y(self, value: Any = None) -> Any:
        """The y component; ``y(s)`` sets it."""
        if value is None:
            return self._d[1]
        self._d[1] = _number(value, "Vector.y")
        return None

    def z(self, value: Any = None) -> Any:
        """The z component; ``z(s)`` sets it."""
        if value is None:
            return self._d[2]
        self._d[2] = _number(value, "Vector.z")
        return None

    def __getitem__(self, i: int) -> float:
        if i.__class__ is int and 0 <= i < 3:
            return self._d[i]
        return self._d[_index(i, 3, "Vector")]

    def __setitem__(self, i: int, value: float) -> None:
        self._d[_index(i, 3, "Vector")] = _number(value, "a Vector element")

    def __iter__(self):
        return iter(self._d)

    def __repr__(self) -> str:
        x, y, z = self._d
        return f"[{_fmt(x)},{_fmt(y)},{_fmt(z)}]"

    # -- arithmetic
    def __add__(self, other: Any) -> Any:
        if other.__class__ is not Vector and not isinstance(other, Vector):
            return NotImplemented
        a, b, c = self._d
        x, y, z = other._d
        r = _new(Vector)
        r._d = [a + x, b + y, c + z]
        return r

    def __sub__(self, other: Any) -> Any:
        if other.__class__ is not Vector and not isinstance(other, Vector):
            return NotImplemented
        a, b, c = self._d
        x, y, z = other._d
        r = _new(Vector)
        r._d = [a - x, b - y, c - z]
        return r

    def __iadd__(self, other: Any) -> Any:
        if not isinstance(other, Vector):
            return NotImplemented
        d, o = self._d, other._d
        d[0] += o[0]
        d[1] += o[1]
        d[2] += o[2]
        return self

    def __isub__(self, other: Any) -> Any:
        if not isinstance(other, Vector):
            return NotImplemented
        d, o = self._d, other._d
        d[0] -= o[0]
        d[1] -= o[1]
        d[2] -= o[2]
        return self

    def __mul__(self, other: Any) -> Any:
        c = other.__class__
        if c is float or c is int:
            x, y, z = self._d
            r = _new(Vector)
            r._d = [x * other, y * other, z * other]
            return r
        if c is Vector or isinstance(other, Vector):
            r = _new(Vector)
            r._d = _cross(self._d, other._d)
            return r
        s = _scale_of(other)
        if s is None:
            return NotImplemented
        return _vector(*[x * s for x in self._d])

    def __rmul__(self, other: Any) -> Any:
        s = _scale_of(other)
        if s is None:
            return NotImplemented
        x, y, z = self._d
        r = _new(Vector)
        r._d = [s * x, s * y, s * z]
        return r

    def __truediv__(self, other: Any) -> Any:
        s = _scale_of(other)
        if s is None:
            return NotImplemented
        r = _new(Vector)
        r._d = _divide(self._d, s)
        return r

    def __neg__(self) -> Vector:
        x, y, z = self._d
        r = _new(Vector)
        r._d = [-x, -y, -z]
        return r

    def __eq__(self, other: Any) -> Any:
        if not isinstance(other, Vector):
            return NotImplemented
        return _close(self._d, other._d, EPSILON)

    def __ne__(self, other: Any) -> Any:
        if not isinstance(other, Vector):
            return NotImplemented
        return not _close(self._d, other._d, EPSILON)

    # -- KDL methods
    def ReverseSign(self) -> None:  # noqa: N802 (KDL's names)
        """Negate in place."""
        d = self._d
        d[0], d[1], d[2] = -d[0], -d[1], -d[2]

    @staticmethod
    def Zero() -> Vector:  # noqa: N802
        return _vector(0.0, 0.0, 0.0)

    def Norm(self, eps: float = EPSILON) -> float:  # noqa: N802
        """The length (0 when every component is below ``eps``)."""
        x, y, z = self._d
        return _norm3(x, y, z, eps)

    def Normalize(self, eps: float = EPSILON) -> float:  # noqa: N802
        """Scale to unit length in place and return the old length; a vector shorter than
        ``eps`` becomes (1, 0, 0) and 0 is returned."""
        d, n = _normalized(*self._d, eps)
        self._d = d
        return n

    # -- copies and pickling
    def __copy__(self) -> Vector:
        return _vector(*self._d)

    def __deepcopy__(self, memo: Any) -> Vector:
        return _vector(*self._d)

    def __getstate__(self) -> Tuple[float, float, float]:
        return tuple(self._d)

    def __setstate__(self, state: Sequence[float]) -> None:
        if len(state) != 3:
            raise RuntimeError("Invalid state!")
        self._d = [float(v) for v in state]

    def __reduce__(self) -> Any:
        return (Vector, tuple(self._d))


class Rotation:
    """A rotation matrix. ``Rotation()`` is the identity; ``Rotation(xx, yx, zx, xy, yy, zy,
    xz, yz, zz)`` takes the nine elements row by row; ``Rotation(x, y, z)`` the three column
    Vectors; ``Rotation(other)`` copies. ``R[i, j]`` reads and writes an element."""

    __slots__ = ("_d",)
    _NAMES = ("xx", "yx", "zx", "xy", "yy", "zy", "xz", "yz", "zz")

    def __init__(self, *args: Any, **kwargs: Any) -> None:
        if kwargs:
            names = ("x", "y", "z") if "x" in kwargs else self._NAMES
            args = args + tuple(_kwargs_in_order(kwargs, names[len(args):], "Rotation"))
        n = len(args)
        if n == 0:
            self._d = [1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0]
        elif n == 9:
            try:
                self._d = [float(a) for a in args]
            except (TypeError, ValueError):
                raise TypeError("Rotation(xx, yx, zx, xy, yy, zy, xz, yz, zz) takes nine "
                                f"numbers; got {args!r}") from None
        elif n == 3 and all(isinstance(a, Vector) for a in args):
            (a, d, g), (b, e, h), (c, f, i) = args[0]._d, args[1]._d, args[2]._d
            self._d = [a, b, c, d, e, f, g, h, i]
        elif n == 1 and isinstance(args[0], Rotation):
            self._d = args[0]._d[:]
        else:
            raise TypeError("Rotation() takes no arguments, nine numbers (row by row), three "
                            f"column Vectors or a Rotation; got {args!r}")

    def __getitem__(self, idx: Any) -> float:
        return self._d[_index2(idx, 3, 3, "Rotation")]

    def __setitem__(self, idx: Any, value: float) -> None:
        self._d[_index2(idx, 3, 3, "Rotation")] = _number(value, "a Rotation element")

    def __repr__(self) -> str:
        d = [_fmt(x) for x in self._d]
        return (f"[{d[0]},{d[1]},{d[2]};\n {d[3]},{d[4]},{d[5]};\n {d[6]},{d[7]},{d[8]}]")

    # -- products
    def __mul__(self, other: Any) -> Any:
        c = other.__class__
        if c is Vector:
            a, b, c_, d, e, f, g, h, i = self._d
            x, y, z = other._d
            r = _new(Vector)
            r._d = [a * x + b * y + c_ * z, d * x + e * y + f * z, g * x + h * y + i * z]
            return r
        if c is Rotation:
            r = _new(Rotation)
            r._d = _rot_rot(self._d, other._d)
            return r
        if isinstance(other, Twist):
            return _twist(_rot_mul(self._d, other._vel._d), _rot_mul(self._d, other._rot._d))
        if isinstance(other, Wrench):
            return _wrench(_rot_mul(self._d, other._force._d), _rot_mul(self._d, other._torque._d))
        if isinstance(other, Vector):
            return _vector(*_rot_mul(self._d, other._d))
        if isinstance(other, Rotation):
            return _rotation(_rot_rot(self._d, other._d))
        return NotImplemented

    def Inverse(self, arg: Any = None) -> Any:  # noqa: N802
        """The inverse (transpose); ``Inverse(x)`` applies it to a Vector, Twist or Wrench."""
        if arg is None:
            return _rotation(_transpose(self._d))
        if isinstance(arg, Vector):
            return _vector(*_rot_tmul(self._d, arg._d))
        if isinstance(arg, Twist):
            return _twist(_rot_tmul(self._d, arg._vel._d), _rot_tmul(self._d, arg._rot._d))
        if isinstance(arg, Wrench):
            return _wrench(_rot_tmul(self._d, arg._force._d), _rot_tmul(self._d, arg._torque._d))
        raise TypeError("Rotation.Inverse() takes nothing, a Vector, a Twist or a Wrench; "
                        f"got {type(arg).__name__}")

    def SetInverse(self) -> None:  # noqa: N802
        """Transpose in place."""
        self._d = _transpose(self._d)

    def __eq__(self, other: Any) -> Any:
        if not isinstance(other, Rotation):
            return NotImplemented
        return _close(self._d, other._d, EPSILON)

    def __ne__(self, other: Any) -> Any:
        if not isinstance(other, Rotation):
            return NotImplemented
        return not _close(self._d, other._d, EPSILON)

    # -- constructors
    @staticmethod
    def Identity() -> Rotation:  # noqa: N802
        return _rotation([1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0])

    @staticmethod
    def RotX(angle: float) -> Rotation:  # noqa: N802
        cs, sn = _cos(angle), _sin(angle)
        return _rotation([1.0, 0.0, 0.0, 0.0, cs, -sn, 0.0, sn, cs])

    @staticmethod
    def RotY(angle: float) -> Rotation:  # noqa: N802
        cs, sn = _cos(angle), _sin(angle)
        return _rotation([cs, 0.0, sn, 0.0, 1.0, 0.0, -sn, 0.0, cs])

    @staticmethod
    def RotZ(angle: float) -> Rotation:  # noqa: N802
        cs, sn = _cos(angle), _sin(angle)
        return _rotation([cs, -sn, 0.0, sn, cs, 0.0, 0.0, 0.0, 1.0])

    @staticmethod
    def Rot(rotvec: Vector, angle: float) -> Rotation:  # noqa: N802
        """The rotation of ``angle`` about ``rotvec`` (normalised first; a zero vector is
        taken as the x axis, as KDL does)."""
        axis, _ = _normalized(*rotvec._d)
        return _rotation(_rot2(axis, angle))

    @staticmethod
    def Rot2(rotvec: Vector, angle: float) -> Rotation:  # noqa: N802
        """The rotation of ``angle`` about ``rotvec``, which must be a unit vector."""
        return _rotation(_rot2(rotvec._d, angle))

    @staticmethod
    def RPY(roll: float, pitch: float, yaw: float) -> Rotation:  # noqa: N802
        """Roll about x, then pitch about y, then yaw about z, all about the fixed axes."""
        ca, sa = _cos(yaw), _sin(yaw)
        cb, sb = _cos(pitch), _sin(pitch)
        cc, sc = _cos(roll), _sin(roll)
        casb, sasb = ca * sb, sa * sb  # (ca sb) sc is how "ca*sb*sc" is evaluated
        r = _new(Rotation)
        r._d = [ca * cb, casb * sc - sa * cc, casb * cc + sa * sc,
                sa * cb, sasb * sc + ca * cc, sasb * cc - ca * sc,
                -sb, cb * sc, cb * cc]
        return r

    @staticmethod
    def EulerZYX(alpha: float, beta: float, gamma: float) -> Rotation:  # noqa: N802
        """Rotations about z, then the new y, then the new x: RPY(gamma, beta, alpha)."""
        return Rotation.RPY(gamma, beta, alpha)

    @staticmethod
    def EulerZYZ(alpha: float, beta: float, gamma: float) -> Rotation:  # noqa: N802
        sa, ca = _sin(alpha), _cos(alpha)
        sb, cb = _sin(beta), _cos(beta)
        sg, cg = _sin(gamma), _cos(gamma)
        return _rotation([ca * cb * cg - sa * sg, -ca * cb * sg - sa * cg, ca * sb,
                          sa * cb * cg + ca * sg, -sa * cb * sg + ca * cg, sa * sb,
                          -sb * cg, sb * sg, cb])

    @staticmethod
    def Quaternion(x: float, y: float, z: float, w: float) -> Rotation:  # noqa: N802
        """The rotation of quaternion (x, y, z, w) (not normalised: a non-unit quaternion
        scales the matrix, as in KDL)."""
        x2, y2, z2, w2 = x * x, y * y, z * z, w * w
        tx, ty, tw = 2 * x, 2 * y, 2 * w  # (2 x) y is how "2*x*y" is evaluated
        r = _new(Rotation)
        r._d = [w2 + x2 - y2 - z2, tx * y - tw * z, tx * z + tw * y,
                tx * y + tw * z, w2 - x2 + y2 - z2, ty * z - tw * x,
                tx * z - tw * y, ty * z + tw * x, w2 - x2 - y2 + z2]
        return r

    # -- in-place rotations about the current axes: R = R * Rot?(angle)
    def DoRotX(self, angle: float) -> None:  # noqa: N802
        cs, sn = _cos(angle), _sin(angle)
        d = self._d
        for r in (0, 3, 6):
            a, b = d[r + 1], d[r + 2]
            d[r + 1], d[r + 2] = cs * a + sn * b, -sn * a + cs * b

    def DoRotY(self, angle: float) -> None:  # noqa: N802
        cs, sn = _cos(angle), _sin(angle)
        d = self._d
        for r in (0, 3, 6):
            a, b = d[r], d[r + 2]
            d[r], d[r + 2] = cs * a - sn * b, sn * a + cs * b

    def DoRotZ(self, angle: float) -> None:  # noqa: N802
        cs, sn = _cos(angle), _sin(angle)
        d = self._d
        for r in (0, 3, 6):
            a, b = d[r], d[r + 1]
            d[r], d[r + 1] = cs * a + sn * b, -sn * a + cs * b

    # -- conversions
    def GetRot(self) -> Vector:  # noqa: N802
        """The rotation vector: the axis scaled by the angle."""
        angle, (x, y, z) = _rot_angle(self._d)
        return _vector(x * angle, y * angle, z * angle)

    def GetRotAngle(self, eps: float = EPSILON) -> Tuple[float, Vector]:  # noqa: N802
        """(angle in [0, pi], axis Vector); the identity's axis is (0, 0, 1)."""
        angle, axis = _rot_angle(self._d, eps)
        return angle, _vector(*axis)

    def GetRPY(self) -> Tuple[float, float, float]:  # noqa: N802
        """(roll, pitch, yaw) of RPY; at pitch = +-pi/2 roll is 0."""
        d = self._d
        pitch = _atan2(-d[6], _sqrt(d[0] * d[0] + d[3] * d[3]))
        if abs(pitch) > _HALF_PI - 1e-12:
            return 0.0, pitch, _atan2(-d[1], d[4])
        return _atan2(d[7], d[8]), pitch, _atan2(d[3], d[0])

    def GetEulerZYX(self) -> Tuple[float, float, float]:  # noqa: N802
        """(alpha, beta, gamma) of EulerZYX: GetRPY reversed."""
        roll, pitch, yaw = self.GetRPY()
        return yaw, pitch, roll

    def GetEulerZYZ(self) -> Tuple[float, float, float]:  # noqa: N802
        d = self._d
        if abs(d[8]) > 1 - 1e-12:
            if d[8] > 0:
                return _atan2(d[3], d[0]), 0.0, 0.0
            return _atan2(-d[3], -d[0]), _PI, 0.0
        return (_atan2(d[5], d[2]), _atan2(_sqrt(d[6] * d[6] + d[7] * d[7]), d[8]),
                _atan2(d[7], -d[6]))

    def GetQuaternion(self) -> Tuple[float, float, float, float]:  # noqa: N802
        """(x, y, z, w), through the largest of the trace and the diagonal (w >= 0 unless the
        rotation is near a half turn), as KDL computes it."""
        d0, d1, d2, d3, d4, d5, d6, d7, d8 = self._d
        trace = d0 + d4 + d8
        if trace > 1e-12:
            s = 0.5 / _sqrt(trace + 1.0)
            return (d7 - d5) * s, (d2 - d6) * s, (d3 - d1) * s, 0.25 / s
        if d0 > d4 and d0 > d8:
            s = 2.0 * _safe_sqrt(1.0 + d0 - d4 - d8)
            return 0.25 * s, _ieee_div(d1 + d3, s), _ieee_div(d2 + d6, s), _ieee_div(d7 - d5, s)
        if d4 > d8:
            s = 2.0 * _safe_sqrt(1.0 + d4 - d0 - d8)
            return _ieee_div(d1 + d3, s), 0.25 * s, _ieee_div(d5 + d7, s), _ieee_div(d2 - d6, s)
        s = 2.0 * _safe_sqrt(1.0 + d8 - d0 - d4)
        return _ieee_div(d2 + d6, s), _ieee_div(d5 + d7, s), 0.25 * s, _ieee_div(d3 - d1, s)

    def UnitX(self, v: Any = None) -> Any:  # noqa: N802
        """The first column; ``UnitX(v)`` sets it."""
        return self._column(0, v)

    def UnitY(self, v: Any = None) -> Any:  # noqa: N802
        """The second column; ``UnitY(v)`` sets it."""
        return self._column(1, v)

    def UnitZ(self, v: Any = None) -> Any:  # noqa: N802
        """The third column; ``UnitZ(v)`` sets it."""
        return self._column(2, v)

    def _column(self, j: int, v: Any) -> Any:
        d = self._d
        if v is None:
            return _vector(d[j], d[j + 3], d[j + 6])
        if not isinstance(v, Vector):
            raise TypeError(f"a Rotation's column is a Vector, got {type(v).__name__}")
        d[j], d[j + 3], d[j + 6] = v._d
        return None

    # -- copies and pickling
    def __copy__(self) -> Rotation:
        return _rotation(self._d[:])

    def __deepcopy__(self, memo: Any) -> Rotation:
        return _rotation(self._d[:])

    def __getstate__(self) -> Tuple[float, float, float]:
        """PyKDL's state: the RPY angles."""
        return self.GetRPY()

    def __setstate__(self, state: Sequence[float]) -> None:
        if len(state) != 3:
            raise RuntimeError("Invalid state!")
        self._d = Rotation.RPY(*state)._d

    def __reduce__(self) -> Any:
        # the nine numbers (exact), not PyKDL's RPY state (which loses a non-orthonormal matrix)
        return (Rotation, tuple(self._d))


def _kwargs_in_order(kwargs: dict, names: Sequence[str], what: str) -> List[Any]:
    """Keyword arguments as positional ones in ``names``' order; others are a TypeError."""
    kwargs = dict(kwargs)
    out = []
    for name in names:
        if name not in kwargs:
            break
        out.append(kwargs.pop(name))
    if kwargs:
        raise TypeError(f"{what}() got unexpected keyword arguments {sorted(kwargs)}")
    return out


class Frame:
    """A pose: rotation ``M`` and position ``p``; ``Frame()``, ``Frame(R, V)``, ``Frame(V)``,
    ``Frame(R)`` or ``Frame(other)``. ``F * v`` maps a point, ``F * G`` composes, ``F[i, j]``
    reads the 3x4 matrix [M | p]."""

    __slots__ = ("_M", "_p", "header")

    def __init__(self, R: Any = None, V: Any = None) -> None:  # noqa: N803 (PyKDL's names)
        if R is None or isinstance(R, Rotation):
            m = R._d[:] if R is not None else [1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0]
            if V is None:
                p = [0.0, 0.0, 0.0]
            elif isinstance(V, Vector):
                p = V._d[:]
            else:
                raise TypeError(f"Frame(R, V): V must be a Vector, got {type(V).__name__}")
        elif V is None and isinstance(R, Vector):
            m, p = [1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0], R._d[:]
        elif V is None and isinstance(R, Frame):
            m, p = R._M._d[:], R._p._d[:]
        else:
            raise TypeError("Frame() takes no arguments, (Rotation, Vector), a Rotation, a "
                            f"Vector or a Frame; got {type(R).__name__}, {type(V).__name__}")
        r = _new(Rotation)
        r._d = m
        v = _new(Vector)
        v._d = p
        self._M = r
        self._p = v

    @property
    def M(self) -> Rotation:  # noqa: N802
        """The rotation (the frame's own object: changing it changes the frame)."""
        return self._M

    @M.setter
    def M(self, value: Rotation) -> None:  # noqa: N802
        if not isinstance(value, Rotation):
            raise TypeError(f"Frame.M must be a Rotation, got {type(value).__name__}")
        self._M._d = value._d[:]

    @property
    def p(self) -> Vector:
        """The position (the frame's own object: changing it changes the frame)."""
        return self._p

    @p.setter
    def p(self, value: Vector) -> None:
        if not isinstance(value, Vector):
            raise TypeError(f"Frame.p must be a Vector, got {type(value).__name__}")
        self._p._d = value._d[:]

    def __getitem__(self, idx: Any) -> float:
        k = _index2(idx, 3, 4, "Frame")
        i, j = divmod(k, 4)
        return self._p._d[i] if j == 3 else self._M._d[i * 3 + j]

    def __setitem__(self, idx: Any, value: float) -> None:
        k = _index2(idx, 3, 4, "Frame")
        i, j = divmod(k, 4)
        value = _number(value, "a Frame element")
        if j == 3:
            self._p._d[i] = value
        else:
            self._M._d[i * 3 + j] = value

    def __repr__(self) -> str:
        return f"[{self._M!r}\n{self._p!r}]"

    def __mul__(self, other: Any) -> Any:
        c = other.__class__
        if c is Vector:
            a, b, c_, d, e, f, g, h, i = self._M._d
            px, py, pz = self._p._d
            x, y, z = other._d
            r = _new(Vector)
            r._d = [a * x + b * y + c_ * z + px, d * x + e * y + f * z + py,
                    g * x + h * y + i * z + pz]
            return r
        if c is Frame:
            a, b, c_, d, e, f, g, h, i = self._M._d
            A, B, C, D, E, F, G, H, I = other._M._d  # noqa: N806, E741
            px, py, pz = self._p._d
            x, y, z = other._p._d
            m = _new(Rotation)
            m._d = [a * A + b * D + c_ * G, a * B + b * E + c_ * H, a * C + b * F + c_ * I,
                    d * A + e * D + f * G, d * B + e * E + f * H, d * C + e * F + f * I,
                    g * A + h * D + i * G, g * B + h * E + i * H, g * C + h * F + i * I]
            v = _new(Vector)
            v._d = [a * x + b * y + c_ * z + px, d * x + e * y + f * z + py,
                    g * x + h * y + i * z + pz]
            r = _new(Frame)
            r._M = m
            r._p = v
            return r
        if isinstance(other, Twist):
            m, p = self._M._d, self._p._d
            rot = _rot_mul(m, other._rot._d)
            vx, vy, vz = _rot_mul(m, other._vel._d)
            cx, cy, cz = _cross(p, rot)
            return _twist([vx + cx, vy + cy, vz + cz], rot)
        if isinstance(other, Wrench):
            m, p = self._M._d, self._p._d
            force = _rot_mul(m, other._force._d)
            tx, ty, tz = _rot_mul(m, other._torque._d)
            cx, cy, cz = _cross(p, force)
            return _wrench(force, [tx + cx, ty + cy, tz + cz])
        if isinstance(other, Vector):
            return self * _vector(*other._d)
        if isinstance(other, Frame):
            return self * _frame(other._M._d[:], other._p._d[:])
        return NotImplemented

    def Inverse(self, arg: Any = None) -> Any:  # noqa: N802
        """The inverse frame; ``Inverse(x)`` applies it to a Vector, Twist or Wrench."""
        m, p = self._M._d, self._p._d
        if arg is None:
            a, b, c, d, e, f, g, h, i = m
            x, y, z = p
            r = _new(Rotation)
            r._d = [a, d, g, b, e, h, c, f, i]
            v = _new(Vector)
            v._d = [-(a * x + d * y + g * z), -(b * x + e * y + h * z), -(c * x + f * y + i * z)]
            out = _new(Frame)
            out._M = r
            out._p = v
            return out
        if isinstance(arg, Vector):
            x, y, z = arg._d
            return _vector(*_rot_tmul(m, (x - p[0], y - p[1], z - p[2])))
        if isinstance(arg, Twist):
            vx, vy, vz = arg._vel._d
            cx, cy, cz = _cross(p, arg._rot._d)
            return _twist(_rot_tmul(m, (vx - cx, vy - cy, vz - cz)), _rot_tmul(m, arg._rot._d))
        if isinstance(arg, Wrench):
            tx, ty, tz = arg._torque._d
            cx, cy, cz = _cross(p, arg._force._d)
            return _wrench(_rot_tmul(m, arg._force._d), _rot_tmul(m, (tx - cx, ty - cy, tz - cz)))
        raise TypeError("Frame.Inverse() takes nothing, a Vector, a Twist or a Wrench; "
                        f"got {type(arg).__name__}")

    def Integrate(self, t_this: Twist, samplefrequency: float) -> None:  # noqa: N802
        """Move the frame by twist ``t_this`` (in the frame's own coordinates) for one period
        of ``samplefrequency``."""
        rx, ry, rz = t_this._rot._d
        n = _norm3(rx, ry, rz) / samplefrequency
        vel = _divide(t_this._vel._d, samplefrequency)
        if n < EPSILON:
            dx, dy, dz = _rot_mul(self._M._d, vel)
            p = self._p._d
            p[0] += dx
            p[1] += dy
            p[2] += dz
            return
        axis, _ = _normalized(rx, ry, rz)
        moved = self * _frame(_rot2(axis, n), vel)
        self._M._d, self._p._d = moved._M._d, moved._p._d

    @staticmethod
    def Identity() -> Frame:  # noqa: N802
        return _frame([1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0], [0.0, 0.0, 0.0])

    @staticmethod
    def DH(a: float, alpha: float, d: float, theta: float) -> Frame:  # noqa: N802
        """The frame of Denavit-Hartenberg parameters."""
        ct, st, ca, sa = _cos(theta), _sin(theta), _cos(alpha), _sin(alpha)
        return _frame([ct, -st * ca, st * sa, st, ct * ca, -ct * sa, 0.0, sa, ca],
                      [a * ct, a * st, float(d)])

    @staticmethod
    def DH_Craig1989(a: float, alpha: float, d: float, theta: float) -> Frame:  # noqa: N802
        """The frame of modified Denavit-Hartenberg parameters (Craig's convention)."""
        ct, st, ca, sa = _cos(theta), _sin(theta), _cos(alpha), _sin(alpha)
        return _frame([ct, -st, 0.0, st * ca, ct * ca, -sa, st * sa, ct * sa, ca],
                      [float(a), -sa * d, ca * d])

    def __eq__(self, other: Any) -> Any:
        if not isinstance(other, Frame):
            return NotImplemented
        return _close(self._M._d, other._M._d, EPSILON) and _close(self._p._d, other._p._d, EPSILON)

    def __ne__(self, other: Any) -> Any:
        if not isinstance(other, Frame):
            return NotImplemented
        return not self.__eq__(other)

    def __copy__(self) -> Frame:
        return _frame(self._M._d[:], self._p._d[:])

    def __deepcopy__(self, memo: Any) -> Frame:
        return _frame(self._M._d[:], self._p._d[:])

    def __getstate__(self) -> Tuple[Rotation, Vector]:
        return (_rotation(self._M._d[:]), _vector(*self._p._d))

    def __setstate__(self, state: Sequence[Any]) -> None:
        if len(state) != 2:
            raise RuntimeError("Invalid state!")
        self._M = _rotation(state[0]._d[:])
        self._p = _vector(*state[1]._d)

    def __reduce__(self) -> Any:
        return (Frame, (_rotation(self._M._d[:]), _vector(*self._p._d)))


class _Screw:
    """What Twist and Wrench share: two Vectors, six indexed numbers, the linear operators."""

    __slots__ = ()
    _FIRST = _SECOND = ""

    def _pair(self) -> Tuple[List[float], List[float]]:
        raise NotImplementedError

    def _make(self, a: List[float], b: List[float]) -> Any:
        raise NotImplementedError

    def __getitem__(self, i: int) -> float:
        i = _index(i, 6, type(self).__name__)
        a, b = self._pair()
        return a[i] if i < 3 else b[i - 3]

    def __setitem__(self, i: int, value: float) -> None:
        i = _index(i, 6, type(self).__name__)
        a, b = self._pair()
        value = _number(value, f"a {type(self).__name__} element")
        if i < 3:
            a[i] = value
        else:
            b[i - 3] = value

    def __repr__(self) -> str:
        a, b = self._pair()
        return "[" + ",".join(_fmt(x) for x in (*a, *b)) + "]"

    def __add__(self, other: Any) -> Any:
        if type(other) is not type(self):
            return NotImplemented
        (a, b, c), (d, e, f) = self._pair()
        (x, y, z), (u, v, w) = other._pair()
        return self._make([a + x, b + y, c + z], [d + u, e + v, f + w])

    def __sub__(self, other: Any) -> Any:
        if type(other) is not type(self):
            return NotImplemented
        (a, b, c), (d, e, f) = self._pair()
        (x, y, z), (u, v, w) = other._pair()
        return self._make([a - x, b - y, c - z], [d - u, e - v, f - w])

    def __iadd__(self, other: Any) -> Any:
        if type(other) is not type(self):
            return NotImplemented
        for mine, theirs in zip(self._pair(), other._pair()):
            for k in range(3):
                mine[k] += theirs[k]
        return self

    def __isub__(self, other: Any) -> Any:
        if type(other) is not type(self):
            return NotImplemented
        for mine, theirs in zip(self._pair(), other._pair()):
            for k in range(3):
                mine[k] -= theirs[k]
        return self

    def __mul__(self, other: Any) -> Any:
        s = _scale_of(other)
        if s is None:
            return NotImplemented
        a, b = self._pair()
        return self._make([x * s for x in a], [x * s for x in b])

    def __rmul__(self, other: Any) -> Any:
        s = _scale_of(other)
        if s is None:
            return NotImplemented
        a, b = self._pair()
        return self._make([s * x for x in a], [s * x for x in b])

    def __truediv__(self, other: Any) -> Any:
        s = _scale_of(other)
        if s is None:
            return NotImplemented
        a, b = self._pair()
        return self._make(_divide(a, s), _divide(b, s))

    def __neg__(self) -> Any:
        a, b = self._pair()
        return self._make([-x for x in a], [-x for x in b])

    def __eq__(self, other: Any) -> Any:
        if type(other) is not type(self):
            return NotImplemented
        a, b = self._pair()
        x, y = other._pair()
        return _close(a, x, EPSILON) and _close(b, y, EPSILON)

    def __ne__(self, other: Any) -> Any:
        if type(other) is not type(self):
            return NotImplemented
        return not self.__eq__(other)

    def ReverseSign(self) -> None:  # noqa: N802
        """Negate in place."""
        for part in self._pair():
            part[0], part[1], part[2] = -part[0], -part[1], -part[2]

    def __copy__(self) -> Any:
        a, b = self._pair()
        return self._make(a[:], b[:])

    def __deepcopy__(self, memo: Any) -> Any:
        return self.__copy__()

    def __getstate__(self) -> Tuple[Vector, Vector]:
        a, b = self._pair()
        return (_vector(*a), _vector(*b))

    def __reduce__(self) -> Any:
        return (type(self), self.__getstate__())


class Twist(_Screw):
    """A velocity screw: linear ``vel`` and angular ``rot``; ``Twist()``, ``Twist(vel, rot)`` or
    ``Twist(other)``. ``t[0:3]`` are vel, ``t[3:6]`` rot."""

    __slots__ = ("_vel", "_rot", "header")

    def __init__(self, vel: Any = None, rot: Any = None) -> None:
        if vel is None and rot is None:
            a, b = [0.0, 0.0, 0.0], [0.0, 0.0, 0.0]
        elif isinstance(vel, Vector) and isinstance(rot, Vector):
            a, b = vel._d[:], rot._d[:]
        elif rot is None and isinstance(vel, Twist):
            a, b = vel._vel._d[:], vel._rot._d[:]
        else:
            raise TypeError("Twist() takes no arguments, (vel, rot) Vectors or a Twist; got "
                            f"{type(vel).__name__}, {type(rot).__name__}")
        self._vel = _vector(*a)
        self._rot = _vector(*b)

    def _pair(self) -> Tuple[List[float], List[float]]:
        return self._vel._d, self._rot._d

    def _make(self, a: List[float], b: List[float]) -> Twist:
        return _twist(a, b)

    @property
    def vel(self) -> Vector:
        """The linear velocity (the twist's own object)."""
        return self._vel

    @vel.setter
    def vel(self, value: Vector) -> None:
        if not isinstance(value, Vector):
            raise TypeError(f"Twist.vel must be a Vector, got {type(value).__name__}")
        self._vel._d = value._d[:]

    @property
    def rot(self) -> Vector:
        """The angular velocity (the twist's own object)."""
        return self._rot

    @rot.setter
    def rot(self, value: Vector) -> None:
        if not isinstance(value, Vector):
            raise TypeError(f"Twist.rot must be a Vector, got {type(value).__name__}")
        self._rot._d = value._d[:]

    @staticmethod
    def Zero() -> Twist:  # noqa: N802
        return _twist([0.0, 0.0, 0.0], [0.0, 0.0, 0.0])

    def RefPoint(self, base: Vector) -> Twist:  # noqa: N802
        """The same motion referred to the point ``base`` (from the old reference point,
        in the twist's frame): vel + rot x base."""
        vx, vy, vz = self._vel._d
        cx, cy, cz = _cross(self._rot._d, base._d)
        return _twist([vx + cx, vy + cy, vz + cz], self._rot._d[:])

    def __setstate__(self, state: Sequence[Any]) -> None:
        if len(state) != 2:
            raise RuntimeError("Invalid state!")
        self._vel, self._rot = _vector(*state[0]._d), _vector(*state[1]._d)


class Wrench(_Screw):
    """A force screw: ``force`` and ``torque``; ``Wrench()``, ``Wrench(force, torque)`` or
    ``Wrench(other)``. ``w[0:3]`` are force, ``w[3:6]`` torque."""

    __slots__ = ("_force", "_torque", "header")

    def __init__(self, force: Any = None, torque: Any = None) -> None:
        if force is None and torque is None:
            a, b = [0.0, 0.0, 0.0], [0.0, 0.0, 0.0]
        elif isinstance(force, Vector) and isinstance(torque, Vector):
            a, b = force._d[:], torque._d[:]
        elif torque is None and isinstance(force, Wrench):
            a, b = force._force._d[:], force._torque._d[:]
        else:
            raise TypeError("Wrench() takes no arguments, (force, torque) Vectors or a Wrench; "
                            f"got {type(force).__name__}, {type(torque).__name__}")
        self._force = _vector(*a)
        self._torque = _vector(*b)

    def _pair(self) -> Tuple[List[float], List[float]]:
        return self._force._d, self._torque._d

    def _make(self, a: List[float], b: List[float]) -> Wrench:
        return _wrench(a, b)

    @property
    def force(self) -> Vector:
        """The force (the wrench's own object)."""
        return self._force

    @force.setter
    def force(self, value: Vector) -> None:
        if not isinstance(value, Vector):
            raise TypeError(f"Wrench.force must be a Vector, got {type(value).__name__}")
        self._force._d = value._d[:]

    @property
    def torque(self) -> Vector:
        """The torque (the wrench's own object)."""
        return self._torque

    @torque.setter
    def torque(self, value: Vector) -> None:
        if not isinstance(value, Vector):
            raise TypeError(f"Wrench.torque must be a Vector, got {type(value).__name__}")
        self._torque._d = value._d[:]

    @staticmethod
    def Zero() -> Wrench:  # noqa: N802
        return _wrench([0.0, 0.0, 0.0], [0.0, 0.0, 0.0])

    def RefPoint(self, base: Vector) -> Wrench:  # noqa: N802
        """The same wrench referred to the point ``base``: torque + force x base."""
        tx, ty, tz = self._torque._d
        cx, cy, cz = _cross(self._force._d, base._d)
        return _wrench(self._force._d[:], [tx + cx, ty + cy, tz + cz])

    def __setstate__(self, state: Sequence[Any]) -> None:
        if len(state) != 2:
            raise RuntimeError("Invalid state!")
        self._force, self._torque = _vector(*state[0]._d), _vector(*state[1]._d)
