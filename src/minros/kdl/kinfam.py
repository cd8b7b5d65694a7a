"""PyKDL's kinematic family: Joint, Segment, Chain, Tree, the inertias, JntArray, JntArrayVel,
Jacobian and JntSpaceInertiaMatrix.

As in KDL, a Segment stores its tip frame relative to the joint at position 0
(``joint.pose(0).Inverse() * f_tip``), so ``Segment.pose(q) == joint.pose(q) * tip``; a Chain
and a Tree copy the segments they are given (changing a Segment afterwards does not change the
chain), and ``Chain.getSegment`` hands out a copy. Joints and segments also compute their poses
as twelve plain numbers (``_pose12``: the rotation row by row, then the position), which the
solvers compose without building Frame objects.
"""

from __future__ import annotations

import enum
import math
from typing import Any, Callable, Dict, List, Optional, Sequence, Tuple

from .frames import (
    EPSILON,
    Frame,
    Rotation,
    Twist,
    Vector,
    _cross,
    _divide,
    _fmt,
    _frame,
    _index,
    _index2,
    _norm3,
    _number,
    _rot2,
    _rot_mul,
    _scale_of,
    _twist,
    _vector,
    _wrench,
)

__all__ = ["Joint", "RotationalInertia", "RigidBodyInertia", "Segment", "Chain", "Tree",
           "JntArray", "JntArrayVel", "Jacobian", "JntSpaceInertiaMatrix"]

_new = object.__new__
_cos, _sin = math.cos, math.sin
_IDENTITY12 = (1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0)


def _mul12(a: Sequence[float], b: Sequence[float]) -> Tuple[float, ...]:
    """The composition of two poses given as twelve numbers (rotation row by row, position)."""
    a0, a1, a2, a3, a4, a5, a6, a7, a8, ax, ay, az = a
    b0, b1, b2, b3, b4, b5, b6, b7, b8, bx, by, bz = b
    return (a0 * b0 + a1 * b3 + a2 * b6, a0 * b1 + a1 * b4 + a2 * b7, a0 * b2 + a1 * b5 + a2 * b8,
            a3 * b0 + a4 * b3 + a5 * b6, a3 * b1 + a4 * b4 + a5 * b7, a3 * b2 + a4 * b5 + a5 * b8,
            a6 * b0 + a7 * b3 + a8 * b6, a6 * b1 + a7 * b4 + a8 * b7, a6 * b2 + a7 * b5 + a8 * b8,
            a0 * bx + a1 * by + a2 * bz + ax, a3 * bx + a4 * by + a5 * bz + ay,
            a6 * bx + a7 * by + a8 * bz + az)


def _frame12(f: Frame) -> Tuple[float, ...]:
    return (*f._M._d, *f._p._d)


def _to_frame(v: Sequence[float]) -> Frame:
    return _frame(list(v[:9]), list(v[9:]))


class _JointType(enum.IntEnum):
    """The kinds of joint (PyKDL's Joint.JointType)."""

    RotAxis = 0
    RotX = 1
    RotY = 2
    RotZ = 3
    TransAxis = 4
    TransX = 5
    TransY = 6
    TransZ = 7
    Fixed = 8

    def __str__(self) -> str:
        return f"JointType.{self.name}"


_JointType.__name__ = _JointType.__qualname__ = "JointType"
_AXIS_TYPES = (_JointType.RotAxis, _JointType.TransAxis)
_UNIT_AXES = {1: (1.0, 0.0, 0.0), 2: (0.0, 1.0, 0.0), 3: (0.0, 0.0, 1.0),
              5: (1.0, 0.0, 0.0), 6: (0.0, 1.0, 0.0), 7: (0.0, 0.0, 1.0)}
_JOINT_PARAMS = ("type", "scale", "offset", "inertia", "damping", "stiffness")
_AXIS_JOINT_PARAMS = ("origin", "axis") + _JOINT_PARAMS


class Joint:
    """A joint: ``Joint(name, type=Joint.Fixed, scale=1, offset=0, inertia=0, damping=0,
    stiffness=0)`` (the name may be left out), or for an arbitrary axis
    ``Joint(name, origin, axis, Joint.RotAxis or Joint.TransAxis, scale=1, ...)``. The joint's
    position is ``scale * q + offset``."""

    JointType = _JointType
    RotAxis, RotX, RotY, RotZ = (_JointType.RotAxis, _JointType.RotX, _JointType.RotY,
                                 _JointType.RotZ)
    TransAxis, TransX, TransY, TransZ = (_JointType.TransAxis, _JointType.TransX,
                                         _JointType.TransY, _JointType.TransZ)
    Fixed = _JointType.Fixed

    __slots__ = ("_name", "_type", "_scale", "_offset", "_inertia", "_damping", "_stiffness",
                 "_axis", "_origin", "_unit")

    def __init__(self, *args: Any, **kwargs: Any) -> None:
        if len(args) == 1 and not kwargs and isinstance(args[0], Joint):
            other = args[0]
            for name in Joint.__slots__:
                setattr(self, name, getattr(other, name))
            return
        rest = list(args)
        name = "NoName"
        if rest and isinstance(rest[0], str):
            name = rest.pop(0)
        elif "name" in kwargs:
            name = kwargs.pop("name")
            if not isinstance(name, str):
                raise TypeError(f"a Joint's name must be a str, got {type(name).__name__}")
        with_axis = (rest and isinstance(rest[0], Vector)) or "origin" in kwargs
        params = _AXIS_JOINT_PARAMS if with_axis else _JOINT_PARAMS
        if len(rest) > len(params):
            raise TypeError(f"Joint() takes at most {len(params) + 1} arguments, got {len(args)}")
        values = dict(zip(params, rest))
        for key, value in kwargs.items():
            if key not in params or key in values:
                raise TypeError(f"Joint() got an unexpected or repeated argument {key!r}")
            values[key] = value
        try:
            jtype = _JointType(values.get("type", _JointType.Fixed))
        except (ValueError, TypeError):
            raise TypeError(f"a Joint's type is a Joint.JointType (Joint.RotZ, ...), got "
                            f"{values.get('type')!r}") from None
        self._name = name
        self._type = jtype
        self._scale = _number(values.get("scale", 1.0), "Joint's scale")
        self._offset = _number(values.get("offset", 0.0), "Joint's offset")
        self._inertia = _number(values.get("inertia", 0.0), "Joint's inertia")
        self._damping = _number(values.get("damping", 0.0), "Joint's damping")
        self._stiffness = _number(values.get("stiffness", 0.0), "Joint's stiffness")
        if with_axis:
            if jtype not in _AXIS_TYPES:
                raise RuntimeError("Joint(name, origin, axis, type) is for Joint.RotAxis and "
                                   f"Joint.TransAxis; a {jtype.name} joint takes no origin or axis")
            origin, axis = values.get("origin"), values.get("axis")
            if not isinstance(origin, Vector) or not isinstance(axis, Vector):
                raise TypeError("Joint(name, origin, axis, type): origin and axis are Vectors")
            self._origin = tuple(origin._d)
            self._axis = tuple(_divide(axis._d, _norm3(*axis._d)))
        else:
            if jtype in _AXIS_TYPES:
                raise RuntimeError(f"a {jtype.name} joint needs an origin and an axis: "
                                   f"Joint(name, origin, axis, Joint.{jtype.name})")
            self._origin = self._axis = (0.0, 0.0, 0.0)
        # the direction the joint moves along or about (zero for a fixed joint)
        self._unit = self._axis if jtype in _AXIS_TYPES else _UNIT_AXES.get(jtype, (0.0, 0.0, 0.0))

    def _pose12(self, q: float) -> Tuple[float, ...]:
        """The joint's pose at ``q`` as twelve numbers."""
        t = self._type
        if t == 8:
            return _IDENTITY12
        a = self._scale * q + self._offset
        if t == 0:
            return (*_rot2(self._axis, a), *self._origin)
        if t <= 3:
            c, s = _cos(a), _sin(a)
            if t == 3:
                return (c, -s, 0.0, s, c, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0)
            if t == 1:
                return (1.0, 0.0, 0.0, 0.0, c, -s, 0.0, s, c, 0.0, 0.0, 0.0)
            return (c, 0.0, s, 0.0, 1.0, 0.0, -s, 0.0, c, 0.0, 0.0, 0.0)
        if t == 4:
            (ox, oy, oz), (ux, uy, uz) = self._origin, self._axis
            return (1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0, ox + ux * a, oy + uy * a, oz + uz * a)
        p = [0.0, 0.0, 0.0]
        p[t - 5] = a
        return (1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0, *p)

    def _twist6(self, qdot: float) -> Tuple[List[float], List[float]]:
        """(vel, rot) of the joint moving at ``qdot``."""
        t = self._type
        if t == 8:
            return [0.0, 0.0, 0.0], [0.0, 0.0, 0.0]
        s = self._scale * qdot
        if t == 0:
            return [0.0, 0.0, 0.0], [x * s for x in self._axis]
        if t == 4:
            return [x * s for x in self._axis], [0.0, 0.0, 0.0]
        e = [0.0, 0.0, 0.0]
        if t <= 3:
            e[t - 1] = s
            return [0.0, 0.0, 0.0], e
        e[t - 5] = s
        return e, [0.0, 0.0, 0.0]

    def pose(self, q: float) -> Frame:
        """The joint's frame at position ``q``."""
        return _to_frame(self._pose12(_number(q, "q")))

    def twist(self, qdot: float) -> Twist:
        """The joint's twist at velocity ``qdot``."""
        vel, rot = self._twist6(_number(qdot, "qdot"))
        return _twist(vel, rot)

    def JointAxis(self) -> Vector:  # noqa: N802
        if self._type in _AXIS_TYPES:
            return _vector(*self._axis)
        return _vector(*_UNIT_AXES.get(self._type, (0.0, 0.0, 0.0)))

    def JointOrigin(self) -> Vector:  # noqa: N802
        return _vector(*self._origin)

    def getName(self) -> str:  # noqa: N802
        return self._name

    def getType(self) -> _JointType:  # noqa: N802
        return self._type

    def getTypeName(self) -> str:  # noqa: N802
        return self._type.name

    def __repr__(self) -> str:
        return (f"{self._name}:[{self._type.name}, axis: {self.JointAxis()!r}, "
                f"origin{self.JointOrigin()!r}]")


class RotationalInertia:
    """A symmetric 3x3 inertia: ``RotationalInertia(Ixx=0, Iyy=0, Izz=0, Ixy=0, Ixz=0,
    Iyz=0)``; ``I[k]`` reads and writes its nine elements row by row."""

    __slots__ = ("_d",)

    def __init__(self, Ixx: float = 0.0, Iyy: float = 0.0, Izz: float = 0.0,  # noqa: N803
                 Ixy: float = 0.0, Ixz: float = 0.0, Iyz: float = 0.0) -> None:  # noqa: N803
        xx, yy, zz, xy, xz, yz = (_number(v, "an inertia element")
                                  for v in (Ixx, Iyy, Izz, Ixy, Ixz, Iyz))
        self._d = [xx, xy, xz, xy, yy, yz, xz, yz, zz]

    @staticmethod
    def Zero() -> RotationalInertia:  # noqa: N802
        return RotationalInertia()

    def __getitem__(self, i: int) -> float:
        return self._d[_index(i, 9, "RotationalInertia")]

    def __setitem__(self, i: int, value: float) -> None:
        self._d[_index(i, 9, "RotationalInertia")] = _number(value, "an inertia element")

    def __mul__(self, other: Any) -> Any:
        if not isinstance(other, Vector):
            return NotImplemented
        return _vector(*_inertia_mul(self._d, other._d))

    def __rmul__(self, other: Any) -> Any:
        s = _scale_of(other)
        if s is None:
            return NotImplemented
        return _rotational(_scaled(s, self._d))

    def __add__(self, other: Any) -> Any:
        if not isinstance(other, RotationalInertia):
            return NotImplemented
        return _rotational([a + b for a, b in zip(self._d, other._d)])

    def __repr__(self) -> str:
        d = [_fmt(x) for x in self._d]
        return f"RotationalInertia([{d[0]},{d[1]},{d[2]};\n {d[3]},{d[4]},{d[5]};\n {d[6]},{d[7]},{d[8]}])"


def _rotational(d: List[float]) -> RotationalInertia:
    r = _new(RotationalInertia)
    r._d = d
    return r


def _scaled(s: float, d: Sequence[float]) -> List[float]:
    return [s * x for x in d]


def _inertia_mul(d: Sequence[float], w: Sequence[float]) -> List[float]:
    """KDL multiplies through a column-major view of the row-major numbers: the transpose
    (the same matrix while it is symmetric)."""
    x, y, z = w
    return [d[0] * x + d[3] * y + d[6] * z, d[1] * x + d[4] * y + d[7] * z,
            d[2] * x + d[5] * y + d[8] * z]


def _matmul3(a: Sequence[float], b: Sequence[float]) -> List[float]:
    return [sum(a[i * 3 + k] * b[k * 3 + j] for k in range(3)) for i in range(3) for j in range(3)]


def _t3(a: Sequence[float]) -> List[float]:
    return [a[0], a[3], a[6], a[1], a[4], a[7], a[2], a[5], a[8]]


def _shifted_inertia(m: float, h: Sequence[float], inertia: Sequence[float], r: Sequence[float]
                     ) -> Tuple[List[float], List[float]]:
    """(h, I) of a body's inertia referred to the point ``r`` instead of the old origin."""
    hmr = [h[k] - m * r[k] for k in range(3)]
    trace = r[0] * h[0] + r[1] * h[1] + r[2] * h[2] + hmr[0] * r[0] + hmr[1] * r[1] + hmr[2] * r[2]
    out = []
    for a in range(3):
        for b in range(3):
            v = inertia[a * 3 + b] + r[a] * h[b] + hmr[a] * r[b]
            out.append(v - trace if a == b else v)
    return hmr, out


class RigidBodyInertia:
    """A body's mass ``m``, centre of gravity ``oc`` and rotational inertia ``Ic`` about the
    centre of gravity: ``RigidBodyInertia(m=0, oc=Vector.Zero(), Ic=RotationalInertia.Zero())``.
    Internally, as in KDL, the first moment ``h = m oc`` and the inertia about the origin."""

    __slots__ = ("_m", "_h", "_I")

    def __init__(self, m: float = 0.0, oc: Optional[Vector] = None,
                 Ic: Optional[RotationalInertia] = None) -> None:  # noqa: N803
        m = _number(m, "a mass")
        c = oc._d if oc is not None else (0.0, 0.0, 0.0)
        ic = Ic._d if Ic is not None else [0.0] * 9
        if oc is not None and not isinstance(oc, Vector):
            raise TypeError(f"RigidBodyInertia's oc must be a Vector, got {type(oc).__name__}")
        if Ic is not None and not isinstance(Ic, RotationalInertia):
            raise TypeError("RigidBodyInertia's Ic must be a RotationalInertia, got "
                            f"{type(Ic).__name__}")
        self._m = m
        self._h = [m * c[0], m * c[1], m * c[2]]
        cc = c[0] * c[0] + c[1] * c[1] + c[2] * c[2]
        self._I = [ic[a * 3 + b] - m * (c[a] * c[b] - (cc if a == b else 0.0))
                   for a in range(3) for b in range(3)]

    @staticmethod
    def Zero() -> RigidBodyInertia:  # noqa: N802
        return RigidBodyInertia()

    def getMass(self) -> float:  # noqa: N802
        return self._m

    def getCOG(self) -> Vector:  # noqa: N802
        if self._m == 0:
            return _vector(0.0, 0.0, 0.0)
        return _vector(*_divide(self._h, self._m))

    def getRotationalInertia(self) -> RotationalInertia:  # noqa: N802
        """The rotational inertia about the reference point (not the centre of gravity)."""
        return _rotational(self._I[:])

    def RefPoint(self, p: Vector) -> RigidBodyInertia:  # noqa: N802
        """The same body's inertia referred to point ``p``."""
        h, inertia = _shifted_inertia(self._m, self._h, self._I, p._d)
        return _rbi(self._m, h, inertia)

    def __mul__(self, other: Any) -> Any:
        if not isinstance(other, Twist):
            return NotImplemented
        vel, rot = other._vel._d, other._rot._d
        m, h = self._m, self._h
        hr, hv = _cross(h, rot), _cross(h, vel)
        ir = _inertia_mul(self._I, rot)
        return _wrench([m * vel[k] - hr[k] for k in range(3)], [ir[k] + hv[k] for k in range(3)])

    def __rmul__(self, other: Any) -> Any:
        if isinstance(other, Frame):
            mt = other._M._d
            p = other._p._d
            # X = T^-1; its position is -M^T p
            xp = [-(mt[0] * p[0] + mt[3] * p[1] + mt[6] * p[2]),
                  -(mt[1] * p[0] + mt[4] * p[1] + mt[7] * p[2]),
                  -(mt[2] * p[0] + mt[5] * p[1] + mt[8] * p[2])]
            hmr, shifted = _shifted_inertia(self._m, self._h, self._I, xp)
            return _rbi(self._m, _rot_mul(mt, hmr), _matmul3(_matmul3(mt, shifted), _t3(mt)))
        if isinstance(other, Rotation):
            mt = other._d
            return _rbi(self._m, _rot_mul(mt, self._h), _matmul3(_matmul3(mt, self._I), _t3(mt)))
        s = _scale_of(other)
        if s is None:
            return NotImplemented
        return _rbi(s * self._m, _scaled(s, self._h), _scaled(s, self._I))

    def __add__(self, other: Any) -> Any:
        if not isinstance(other, RigidBodyInertia):
            return NotImplemented
        return _rbi(self._m + other._m, [a + b for a, b in zip(self._h, other._h)],
                    [a + b for a, b in zip(self._I, other._I)])

    def __repr__(self) -> str:
        return (f"RigidBodyInertia(m={self._m:g}, cog={self.getCOG()!r}, "
                f"I={self.getRotationalInertia()!r})")


def _rbi(m: float, h: List[float], inertia: List[float]) -> RigidBodyInertia:
    r = _new(RigidBodyInertia)
    r._m, r._h, r._I = m, h, inertia
    return r


_NO_JOINT = Joint()
_ZERO_INERTIA = RigidBodyInertia()


def _pose_kernel(joint: Joint, tip: Tuple[float, ...]) -> Callable[[float], Tuple[float, ...]]:
    """A function of q giving ``joint.pose(q) * tip`` as twelve numbers, written out for the
    joint's type (the zero and unit entries of the joint's frame dropped: the result is the
    same number for number as the full product)."""
    t0, t1, t2, t3, t4, t5, t6, t7, t8, tx, ty, tz = tip
    kind, scale, offset = joint._type, joint._scale, joint._offset
    if kind == 8:
        return lambda q: tip
    if kind == 3:
        def rot_z(q: float) -> Tuple[float, ...]:
            a = scale * q + offset
            c, s = _cos(a), _sin(a)
            return (c * t0 - s * t3, c * t1 - s * t4, c * t2 - s * t5,
                    s * t0 + c * t3, s * t1 + c * t4, s * t2 + c * t5,
                    t6, t7, t8, c * tx - s * ty, s * tx + c * ty, tz)
        return rot_z
    if kind == 2:
        def rot_y(q: float) -> Tuple[float, ...]:
            a = scale * q + offset
            c, s = _cos(a), _sin(a)
            return (c * t0 + s * t6, c * t1 + s * t7, c * t2 + s * t8,
                    t3, t4, t5,
                    -s * t0 + c * t6, -s * t1 + c * t7, -s * t2 + c * t8,
                    c * tx + s * tz, ty, -s * tx + c * tz)
        return rot_y
    if kind == 1:
        def rot_x(q: float) -> Tuple[float, ...]:
            a = scale * q + offset
            c, s = _cos(a), _sin(a)
            return (t0, t1, t2,
                    c * t3 - s * t6, c * t4 - s * t7, c * t5 - s * t8,
                    s * t3 + c * t6, s * t4 + c * t7, s * t5 + c * t8,
                    tx, c * ty - s * tz, s * ty + c * tz)
        return rot_x
    ox, oy, oz = joint._origin
    ux, uy, uz = joint._axis
    if kind == 0:
        def rot_axis(q: float) -> Tuple[float, ...]:
            # Rot2(axis, angle) written out (frames._rot2, the same operations)
            angle = scale * q + offset
            ct, st = _cos(angle), _sin(angle)
            vt = 1 - ct
            vx, vy, vz = vt * ux, vt * uy, vt * uz
            sx, sy, sz = ux * st, uy * st, uz * st
            vxy, vxz, vyz = vx * uy, vx * uz, vy * uz
            a0, a1, a2 = ct + vx * ux, -sz + vxy, sy + vxz
            a3, a4, a5 = sz + vxy, ct + vy * uy, -sx + vyz
            a6, a7, a8 = -sy + vxz, sx + vyz, ct + vz * uz
            return (a0 * t0 + a1 * t3 + a2 * t6, a0 * t1 + a1 * t4 + a2 * t7,
                    a0 * t2 + a1 * t5 + a2 * t8, a3 * t0 + a4 * t3 + a5 * t6,
                    a3 * t1 + a4 * t4 + a5 * t7, a3 * t2 + a4 * t5 + a5 * t8,
                    a6 * t0 + a7 * t3 + a8 * t6, a6 * t1 + a7 * t4 + a8 * t7,
                    a6 * t2 + a7 * t5 + a8 * t8,
                    a0 * tx + a1 * ty + a2 * tz + ox, a3 * tx + a4 * ty + a5 * tz + oy,
                    a6 * tx + a7 * ty + a8 * tz + oz)
        return rot_axis
    if kind == 4:
        def trans_axis(q: float) -> Tuple[float, ...]:
            a = scale * q + offset
            return (t0, t1, t2, t3, t4, t5, t6, t7, t8,
                    tx + (ox + ux * a), ty + (oy + uy * a), tz + (oz + uz * a))
        return trans_axis
    k = kind - 5

    def trans(q: float) -> Tuple[float, ...]:
        p = [tx, ty, tz]
        p[k] += scale * q + offset
        return (t0, t1, t2, t3, t4, t5, t6, t7, t8, p[0], p[1], p[2])
    return trans


class Segment:
    """A rigid link with its joint at the root: ``Segment(name, joint=Joint(),
    f_tip=Frame.Identity(), I=RigidBodyInertia.Zero())`` (the name may be left out);
    ``f_tip`` is the tip frame when the joint is at 0."""

    __slots__ = ("_name", "_joint", "_tip", "_I", "_pose12")

    def __init__(self, *args: Any, **kwargs: Any) -> None:
        if len(args) == 1 and not kwargs and isinstance(args[0], Segment):
            other = args[0]
            self._name, self._joint, self._tip, self._I, self._pose12 = (
                other._name, other._joint, other._tip, other._I, other._pose12)
            return
        rest = list(args)
        name = "NoName"
        if rest and isinstance(rest[0], str):
            name = rest.pop(0)
        elif "name" in kwargs:
            name = kwargs.pop("name")
        params = ("joint", "f_tip", "I")
        if len(rest) > 3:
            raise TypeError(f"Segment() takes at most 4 arguments, got {len(args)}")
        values = dict(zip(params, rest))
        for key, value in kwargs.items():
            if key not in params or key in values:
                raise TypeError(f"Segment() got an unexpected or repeated argument {key!r}")
            values[key] = value
        joint = values.get("joint", _NO_JOINT)
        f_tip = values.get("f_tip")
        inertia = values.get("I", _ZERO_INERTIA)
        if not isinstance(joint, Joint):
            raise TypeError(f"a Segment's joint must be a Joint, got {type(joint).__name__}")
        if f_tip is not None and not isinstance(f_tip, Frame):
            raise TypeError(f"a Segment's f_tip must be a Frame, got {type(f_tip).__name__}")
        if not isinstance(inertia, RigidBodyInertia):
            raise TypeError("a Segment's I must be a RigidBodyInertia, got "
                            f"{type(inertia).__name__}")
        self._name = name
        self._joint = joint
        self._I = inertia
        tip = _frame12(f_tip) if f_tip is not None else _IDENTITY12
        self._tip = _mul12(_frame12(_to_frame(joint._pose12(0.0)).Inverse()), tip)
        self._pose12 = _pose_kernel(joint, self._tip)

    def pose(self, q: float) -> Frame:
        """The tip frame with the joint at ``q``."""
        return _to_frame(self._pose12(_number(q, "q")))

    def _twist6(self, q: float, qdot: float) -> Tuple[List[float], List[float]]:
        """The tip's (vel, rot) in the segment's root frame."""
        vel, rot = self._joint._twist6(qdot)
        jm = self._joint._pose12(q)
        tip = _rot_mul(jm[:9], self._tip[9:])
        c = _cross(rot, tip)
        return [vel[0] + c[0], vel[1] + c[1], vel[2] + c[2]], rot

    def twist(self, q: float, qdot: float) -> Twist:
        """The tip's twist with the joint at ``q`` moving at ``qdot``, in the root frame."""
        vel, rot = self._twist6(_number(q, "q"), _number(qdot, "qdot"))
        return _twist(vel, rot)

    def getFrameToTip(self) -> Frame:  # noqa: N802
        return _to_frame(_mul12(self._joint._pose12(0.0), self._tip))

    def getName(self) -> str:  # noqa: N802
        return self._name

    def getJoint(self) -> Joint:  # noqa: N802
        return Joint(self._joint)

    def getInertia(self) -> RigidBodyInertia:  # noqa: N802
        return self._I

    def setInertia(self, I: RigidBodyInertia) -> None:  # noqa: N802, N803, E741
        if not isinstance(I, RigidBodyInertia):
            raise TypeError(f"setInertia takes a RigidBodyInertia, got {type(I).__name__}")
        self._I = I

    def __repr__(self) -> str:
        return f"{self._name}:[{self._joint!r},\n tip: \n{self.getFrameToTip()!r}]"


def _copy_segment(segment: Segment) -> Segment:
    s = _new(Segment)
    s._name, s._joint, s._tip, s._I, s._pose12 = (segment._name, segment._joint, segment._tip,
                                                  segment._I, segment._pose12)
    return s


class Chain:
    """Segments in a row: ``Chain()`` or ``Chain(other)``; ``addSegment`` appends a copy."""

    __slots__ = ("_segments", "_nj")

    def __init__(self, other: Optional[Chain] = None) -> None:
        self._segments: List[Segment] = []
        self._nj = 0
        if other is not None:
            if not isinstance(other, Chain):
                raise TypeError(f"Chain() takes nothing or a Chain, got {type(other).__name__}")
            self.addChain(other)

    def addSegment(self, segment: Segment) -> None:  # noqa: N802
        if not isinstance(segment, Segment):
            raise TypeError(f"addSegment takes a Segment, got {type(segment).__name__}")
        self._segments.append(_copy_segment(segment))
        if segment._joint._type != 8:
            self._nj += 1

    def addChain(self, chain: Chain) -> None:  # noqa: N802
        if not isinstance(chain, Chain):
            raise TypeError(f"addChain takes a Chain, got {type(chain).__name__}")
        for segment in list(chain._segments):
            self.addSegment(segment)

    def getNrOfJoints(self) -> int:  # noqa: N802
        return self._nj

    def getNrOfSegments(self) -> int:  # noqa: N802
        return len(self._segments)

    def getSegment(self, nr: int) -> Segment:  # noqa: N802
        """A copy of segment ``nr``."""
        n = len(self._segments)
        try:
            i = nr.__index__()
        except AttributeError:
            raise TypeError(f"getSegment takes a segment number, got {type(nr).__name__}") from None
        if not 0 <= i < n:
            raise IndexError(f"getSegment({nr!r}): the chain has {n} segments (0..{n - 1})")
        return _copy_segment(self._segments[i])

    def __repr__(self) -> str:
        return "[" + "".join(f"{s!r}\n" for s in self._segments) + "]"


class _TreeElement:
    __slots__ = ("segment", "parent", "children", "q_nr")

    def __init__(self, segment: Segment, parent: Optional[str], q_nr: int) -> None:
        self.segment, self.parent, self.children, self.q_nr = segment, parent, [], q_nr


class Tree:
    """Segments joined in a tree under a root frame: ``Tree(root_name='root')``;
    ``addSegment(segment, hook_name)`` hangs a copy under segment ``hook_name``."""

    __slots__ = ("_root", "_elements", "_nj")

    def __init__(self, root_name: str = "root") -> None:
        if not isinstance(root_name, str):
            raise TypeError(f"a Tree's root_name is a str, got {type(root_name).__name__}")
        self._root = root_name
        self._elements: Dict[str, _TreeElement] = {root_name: _TreeElement(Segment(root_name), None, 0)}
        self._nj = 0

    def addSegment(self, segment: Segment, hook_name: str) -> bool:  # noqa: N802
        """Add under ``hook_name``; False when that segment is missing or the name is taken."""
        if not isinstance(segment, Segment):
            raise TypeError(f"addSegment takes a Segment, got {type(segment).__name__}")
        parent = self._elements.get(hook_name)
        name = segment._name
        if parent is None or name in self._elements:
            return False
        moving = segment._joint._type != 8
        self._elements[name] = _TreeElement(_copy_segment(segment), hook_name,
                                            self._nj if moving else 0)
        parent.children.append(name)
        if moving:
            self._nj += 1
        return True

    def addChain(self, chain: Chain, hook_name: str) -> bool:  # noqa: N802
        parent = hook_name
        for segment in chain._segments:
            if not self.addSegment(segment, parent):
                return False
            parent = segment._name
        return True

    def addTree(self, tree: Tree, hook_name: str) -> bool:  # noqa: N802
        return self._add_below(tree, tree._root, hook_name)

    def _add_below(self, tree: Tree, name: str, hook_name: str) -> bool:
        for child in tree._elements[name].children:
            if not self.addSegment(tree._elements[child].segment, hook_name):
                return False
            if not self._add_below(tree, child, child):
                return False
        return True

    def getNrOfJoints(self) -> int:  # noqa: N802
        return self._nj

    def getNrOfSegments(self) -> int:  # noqa: N802
        return len(self._elements) - 1

    def _path_to_root(self, name: str) -> List[str]:
        path: List[str] = []
        element = self._elements.get(name)
        while element is not None:
            path.append(name)
            if name == self._root:
                break
            name = element.parent
            element = self._elements.get(name) if name is not None else None
        return path

    def getChain(self, chain_root: str, chain_tip: str) -> Chain:  # noqa: N802
        """The chain from segment ``chain_root`` to ``chain_tip`` (an empty Chain when either
        is missing). Segments walked towards the root are inverted, as KDL does."""
        chain = Chain()
        up, down = self._path_to_root(chain_root), self._path_to_root(chain_tip)
        if not up or up[-1] != self._root or not down or down[-1] != self._root:
            return chain
        common = self._root
        while up and down and up[-1] == down[-1]:
            common = up.pop()
            down.pop()
        up.append(common)
        for here, there in zip(up, up[1:]):
            seg = self._elements[here].segment
            f_tip = seg.pose(0.0).Inverse()
            jnt = seg._joint
            if jnt._type != 8:
                kind = Joint.RotAxis if jnt._type <= 3 else Joint.TransAxis
                jnt = Joint(jnt._name, f_tip * jnt.JointOrigin(), f_tip.M * (-jnt.JointAxis()), kind)
            target = self._elements[there].segment
            chain.addSegment(Segment(target._name, jnt, f_tip, target._I))
        for name in reversed(down):
            chain.addSegment(self._elements[name].segment)
        return chain

    def _text(self, name: str) -> str:
        element = self._elements[name]
        children = "".join(self._text(child) + "\t" for child in element.children)
        return f"{name}(q_nr: {element.q_nr})\n \t{children}\n"

    def __repr__(self) -> str:
        return self._text(self._root)


class JntArray:
    """Joint positions (or velocities, ...): ``JntArray()``, ``JntArray(n)`` (zeros) or
    ``JntArray(other)``; ``q[i]`` reads and writes."""

    __slots__ = ("_d",)

    def __init__(self, size: Any = None) -> None:
        if size is None:
            self._d: List[float] = []
        elif isinstance(size, JntArray):
            self._d = size._d[:]
        else:
            try:
                n = size.__index__()
            except AttributeError:
                raise TypeError("JntArray() takes nothing, a size or a JntArray; got "
                                f"{type(size).__name__}") from None
            if n < 0:
                raise ValueError(f"a JntArray's size cannot be negative ({n})")
            self._d = [0.0] * n

    def rows(self) -> int:
        return len(self._d)

    def columns(self) -> int:
        return 1

    def resize(self, new_size: int) -> None:
        """Change the size, keeping the values that stay and adding zeros."""
        n = new_size.__index__()
        if n < 0:
            raise ValueError(f"a JntArray's size cannot be negative ({n})")
        d = self._d
        self._d = d[:n] if n <= len(d) else d + [0.0] * (n - len(d))

    def __getitem__(self, i: int) -> float:
        d = self._d
        if i.__class__ is int and 0 <= i < len(d):
            return d[i]
        return d[_index(i, len(d), "JntArray")]

    def __setitem__(self, i: int, value: float) -> None:
        d = self._d
        if i.__class__ is int and 0 <= i < len(d) and value.__class__ is float:
            d[i] = value
            return
        d[_index(i, len(d), "JntArray")] = _number(value, "a JntArray element")

    def __iter__(self):
        return iter(self._d)

    def __repr__(self) -> str:
        return "[" + "".join(_fmt(x) for x in self._d) + "]"

    def __eq__(self, other: Any) -> Any:
        if not isinstance(other, JntArray):
            return NotImplemented
        return len(self._d) == len(other._d) and _within(self._d, other._d, EPSILON)


def _within(a: Sequence[float], b: Sequence[float], eps: float) -> bool:
    """Eigen's isZero on the difference: every |a - b| <= eps."""
    return all(abs(x - y) <= eps for x, y in zip(a, b))


def _jnt(d: List[float]) -> JntArray:
    j = _new(JntArray)
    j._d = d
    return j


class JntArrayVel:
    """Joint positions ``q`` with velocities ``qdot``: ``JntArrayVel(n)``,
    ``JntArrayVel(q, qdot)`` or ``JntArrayVel(q)`` (zero velocities)."""

    __slots__ = ("_q", "_qdot")

    def __init__(self, q: Any, qdot: Any = None) -> None:
        if isinstance(q, JntArray):
            self._q = JntArray(q)
            if qdot is None:
                self._qdot = JntArray(len(q._d))
            elif isinstance(qdot, JntArray):
                self._qdot = JntArray(qdot)
            else:
                raise TypeError(f"JntArrayVel(q, qdot): qdot is a JntArray, got {type(qdot).__name__}")
        elif qdot is None:
            self._q, self._qdot = JntArray(q), JntArray(q)
        else:
            raise TypeError("JntArrayVel() takes a size, (q, qdot) JntArrays or a JntArray q")

    q = property(lambda self: self._q, lambda self, value: _set_jnt(self._q, value, "q"),
                 doc="The positions (the object's own JntArray).")
    qdot = property(lambda self: self._qdot, lambda self, value: _set_jnt(self._qdot, value, "qdot"),
                    doc="The velocities (the object's own JntArray).")

    def resize(self, new_size: int) -> None:
        self._q.resize(new_size)
        self._qdot.resize(new_size)

    def value(self) -> JntArray:
        return JntArray(self._q)

    def deriv(self) -> JntArray:
        return JntArray(self._qdot)


def _set_jnt(target: JntArray, value: Any, what: str) -> None:
    if not isinstance(value, JntArray):
        raise TypeError(f"JntArrayVel.{what} must be a JntArray, got {type(value).__name__}")
    target._d = value._d[:]


class Jacobian:
    """A 6 x n matrix, a Twist per joint column: ``Jacobian(n)`` (zeros), ``Jacobian(other)``
    or ``Jacobian()`` (empty); ``J[i, j]`` reads and writes."""

    __slots__ = ("_c", "_rows")

    def __init__(self, columns: Any = None) -> None:
        if columns is None:
            self._c: List[List[float]] = []
            self._rows = 0
        elif isinstance(columns, Jacobian):
            self._c = [c[:] for c in columns._c]
            self._rows = columns._rows
        else:
            try:
                n = columns.__index__()
            except AttributeError:
                raise TypeError("Jacobian() takes nothing, a number of columns or a Jacobian; "
                                f"got {type(columns).__name__}") from None
            if n < 0:
                raise ValueError(f"a Jacobian's number of columns cannot be negative ({n})")
            self._c = [[0.0] * 6 for _ in range(n)]
            self._rows = 6

    def rows(self) -> int:
        return self._rows

    def columns(self) -> int:
        return len(self._c)

    def resize(self, new_nr_of_columns: int) -> None:
        """Change the number of columns, keeping those that stay and adding zero ones."""
        n = new_nr_of_columns.__index__()
        if n < 0:
            raise ValueError(f"a Jacobian's number of columns cannot be negative ({n})")
        c = self._c
        self._c = c[:n] if n <= len(c) else c + [[0.0] * 6 for _ in range(n - len(c))]
        self._rows = 6

    def getColumn(self, i: int) -> Twist:  # noqa: N802
        c = self._c[_index(i, len(self._c), "Jacobian column")]
        return _twist(c[:3], c[3:])

    def setColumn(self, i: int, t: Twist) -> None:  # noqa: N802
        if not isinstance(t, Twist):
            raise TypeError(f"setColumn takes a Twist, got {type(t).__name__}")
        self._c[_index(i, len(self._c), "Jacobian column")] = t._vel._d + t._rot._d

    def changeRefPoint(self, base: Vector) -> None:  # noqa: N802
        """Refer every column to point ``base`` (in place)."""
        self._c = [_col_refpoint(c, base._d) for c in self._c]

    def changeBase(self, rot: Rotation) -> None:  # noqa: N802
        """Rotate every column by ``rot`` (in place)."""
        self._c = [_col_rotate(c, rot._d) for c in self._c]

    def changeRefFrame(self, frame: Frame) -> None:  # noqa: N802
        """Transform every column by ``frame`` (in place)."""
        self._c = [_col_frame(c, frame) for c in self._c]

    def __getitem__(self, idx: Any) -> float:
        k = _index2(idx, self._rows, len(self._c), "Jacobian")
        i, j = divmod(k, len(self._c))
        return self._c[j][i]

    def __setitem__(self, idx: Any, value: float) -> None:
        k = _index2(idx, self._rows, len(self._c), "Jacobian")
        i, j = divmod(k, len(self._c))
        self._c[j][i] = _number(value, "a Jacobian element")

    def __repr__(self) -> str:
        return "[" + "".join("".join(_fmt(c[i]) for c in self._c) + "\n"
                             for i in range(self._rows)) + "]"


def _col_refpoint(c: List[float], base: Sequence[float]) -> List[float]:
    x, y, z = _cross(c[3:], base)
    return [c[0] + x, c[1] + y, c[2] + z, c[3], c[4], c[5]]


def _col_rotate(c: List[float], m: Sequence[float]) -> List[float]:
    return _rot_mul(m, c[:3]) + _rot_mul(m, c[3:])


def _col_frame(c: List[float], frame: Frame) -> List[float]:
    t = frame * _twist(c[:3], c[3:])
    return t._vel._d + t._rot._d


class JntSpaceInertiaMatrix:
    """A joint-space n x n matrix (the mass matrix of ChainDynParam.JntToMass):
    ``JntSpaceInertiaMatrix(n)`` (zeros), ``JntSpaceInertiaMatrix(other)`` or empty."""

    __slots__ = ("_r",)

    def __init__(self, size: Any = None) -> None:
        if size is None:
            self._r: List[List[float]] = []
        elif isinstance(size, JntSpaceInertiaMatrix):
            self._r = [r[:] for r in size._r]
        else:
            try:
                n = size.__index__()
            except AttributeError:
                raise TypeError("JntSpaceInertiaMatrix() takes nothing, a size or a "
                                f"JntSpaceInertiaMatrix; got {type(size).__name__}") from None
            self._r = [[0.0] * n for _ in range(n)]

    def resize(self, new_size: int) -> None:
        """Change the size to n x n (all zeros)."""
        n = new_size.__index__()
        self._r = [[0.0] * n for _ in range(n)]

    def rows(self) -> int:
        return len(self._r)

    def columns(self) -> int:
        return len(self._r)

    def __getitem__(self, idx: Any) -> float:
        n = len(self._r)
        i, j = divmod(_index2(idx, n, n, "Inertia"), max(n, 1))
        return self._r[i][j]

    def __setitem__(self, idx: Any, value: float) -> None:
        n = len(self._r)
        i, j = divmod(_index2(idx, n, n, "Inertia"), max(n, 1))
        self._r[i][j] = _number(value, "an inertia element")

    def __repr__(self) -> str:
        return "[" + "".join("".join(_fmt(x) for x in row) + "\n" for row in self._r) + "]"

    def __eq__(self, other: Any) -> Any:
        if not isinstance(other, JntSpaceInertiaMatrix):
            return NotImplemented
        return len(self._r) == len(other._r) and all(
            _within(a, b, EPSILON) for a, b in zip(self._r, other._r))
