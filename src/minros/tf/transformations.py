"""Homogeneous 4x4 transforms, Euler angles and quaternions with ROS's ``tf.transformations``
conventions, written here from the mathematics.

Conventions (those of ROS 1's ``tf.transformations``, which scripts rely on):

* quaternions are ``[x, y, z, w]`` (PyPI's ``transformations`` and ``transforms3d`` put w
  first: do not mix them);
* matrices act on column vectors: ``numpy.dot(M, [x, y, z, 1])``;
* Euler angles come with a 4-letter axes string: ``'s'`` (static) or ``'r'`` (rotating)
  frame, then the three axes in the order the angles apply: ``'sxyz'`` (the default: roll
  about x, pitch about y, yaw about z, all about the fixed axes) equals ``'rzyx'`` with the
  angle order reversed; the 4-tuple form ``(inner axis, parity, repetition, frame)`` of
  Shoemake's paper is accepted too;
* where a decomposition has several answers (axis/angle sign, a point on an axis or plane),
  the answer rebuilds the same matrix; where it has one (Euler angles, quaternions), the
  numbers and signs are the same as ROS's (checked against Debian's python3-tf).

References: K. Shoemake, "Euler angle conversion", "Uniform random rotations" and "Arcball
rotation control" (Graphics Gems III/IV); S. Thomas, "Decomposing a matrix into simple
transformations" and R. Goldman, "More matrices and transformations" (Graphics Gems II);
W. Kabsch (1978) and B. K. P. Horn (1987) for superimposition.
"""

from __future__ import annotations

import math
from typing import Any, Dict, Optional, Sequence, Tuple

import numpy

__all__ = [
    "identity_matrix", "translation_matrix", "translation_from_matrix", "reflection_matrix",
    "reflection_from_matrix", "rotation_matrix", "rotation_from_matrix", "scale_matrix",
    "scale_from_matrix", "projection_matrix", "projection_from_matrix", "clip_matrix",
    "shear_matrix", "shear_from_matrix", "decompose_matrix", "compose_matrix",
    "orthogonalization_matrix", "superimposition_matrix", "euler_matrix", "euler_from_matrix",
    "euler_from_quaternion", "quaternion_from_euler", "quaternion_about_axis",
    "quaternion_matrix", "quaternion_from_matrix", "quaternion_multiply",
    "quaternion_conjugate", "quaternion_inverse", "quaternion_slerp", "random_quaternion",
    "random_rotation_matrix", "Arcball", "arcball_map_to_sphere", "arcball_constrain_to_axis",
    "arcball_nearest_axis", "vector_norm", "unit_vector", "random_vector", "inverse_matrix",
    "concatenate_matrices", "is_same_transform",
]

#: "close to zero" for the degenerate cases below (4 machine epsilons, as ROS's module)
_EPS = numpy.finfo(float).eps * 4.0

#: the axis that follows axis a in the cyclic order x -> y -> z -> x (index a + 1 allowed)
_NEXT_AXIS = [1, 2, 0, 1]


def _build_axes_table() -> Dict[str, Tuple[int, int, int, int]]:
    """Every axes string and its 4-tuple (inner axis, parity, repetition, frame).

    A static sequence 'sABC' applies A first; its inner axis is A, its parity is odd when B
    does not follow A cyclically, and it repeats when C is A. A rotating sequence 'rABC' is the
    static sequence 'sCBA' with the first and last angle exchanged (frame = 1).
    """
    letters = "xyz"
    table = {}
    for a in range(3):
        for b in range(3):
            if b == a:
                continue
            for c in range(3):
                if c == b:
                    continue
                code = (a, 0 if b == _NEXT_AXIS[a] else 1, 1 if c == a else 0)
                table["s" + letters[a] + letters[b] + letters[c]] = code + (0,)
                table["r" + letters[c] + letters[b] + letters[a]] = code + (1,)
    return table


_AXES2TUPLE = _build_axes_table()
_TUPLE2AXES = {v: k for k, v in _AXES2TUPLE.items()}


def _axes(axes: Any) -> Tuple[int, int, int, int, int, int]:
    """(i, j, k, parity, repetition, frame) of an axes string or 4-tuple."""
    known = _AXES_INFO.get(axes) if isinstance(axes, str) else None
    if known is not None:
        return known
    try:
        first, parity, repetition, frame = _AXES2TUPLE[axes.lower()]
    except (AttributeError, KeyError):
        try:
            first, parity, repetition, frame = _AXES2TUPLE[_TUPLE2AXES[tuple(axes)]]
        except (KeyError, TypeError):
            raise KeyError(f"unknown Euler axes {axes!r}: use one of 'sxyz', 'rzyx', ... "
                           "or a 4-tuple (inner axis, parity, repetition, frame)") from None
    j = _NEXT_AXIS[first + parity]
    k = _NEXT_AXIS[first - parity + 1]
    return first, j, k, parity, repetition, frame


#: the parsed form of every axes string, so that hot loops skip the parsing
_AXES_INFO: Dict[str, Tuple[int, int, int, int, int, int]] = {}
_AXES_INFO.update((name, _axes(name)) for name in _AXES2TUPLE)


def _vec(data: Any, n: int) -> numpy.ndarray:
    return numpy.array(data, dtype=numpy.float64)[:n]


# ----------------------------------------------------------------------------- basics

def identity_matrix() -> numpy.ndarray:
    """The 4x4 identity."""
    return numpy.identity(4)


def translation_matrix(direction: Sequence[float]) -> numpy.ndarray:
    """Translation by ``direction`` (x, y, z)."""
    m = numpy.identity(4)
    m[:3, 3] = _vec(direction, 3)
    return m


def translation_from_matrix(matrix: Any) -> numpy.ndarray:
    """The translation part (x, y, z) of a homogeneous matrix."""
    return numpy.array(matrix, dtype=numpy.float64)[:3, 3].copy()


def vector_norm(data: Any, axis: Optional[int] = None,
                out: Optional[numpy.ndarray] = None) -> Any:
    """Euclidean length of ``data`` (along ``axis``), into ``out`` when given."""
    data = numpy.array(data, dtype=numpy.float64)
    if out is None:
        if data.ndim == 1:
            return math.sqrt(float(numpy.dot(data, data)))
        result = numpy.atleast_1d(numpy.sqrt(numpy.sum(data * data, axis=axis)))
        return result
    numpy.sqrt(numpy.sum(data * data, axis=axis), out=out)
    return None


def unit_vector(data: Any, axis: Optional[int] = None,
                out: Optional[numpy.ndarray] = None) -> Any:
    """``data`` divided by its length (along ``axis``); into ``out`` when given."""
    if out is None:
        data = numpy.array(data, dtype=numpy.float64)
        if data.ndim == 1:
            return data / math.sqrt(float(numpy.dot(data, data)))
    else:
        if out is not data:
            out[:] = numpy.asarray(data)
        data = out
    length = numpy.atleast_1d(numpy.sqrt(numpy.sum(data * data, axis)))
    if axis is not None:
        length = numpy.expand_dims(length, axis)
    if out is None:
        return data / length
    data /= length
    return None


def random_vector(size: Any) -> numpy.ndarray:
    """Uniform random numbers in [0, 1)."""
    return numpy.random.random(size)


def inverse_matrix(matrix: Any) -> numpy.ndarray:
    """Inverse of a square matrix."""
    return numpy.linalg.inv(matrix)


def concatenate_matrices(*matrices: Any) -> numpy.ndarray:
    """The product M0 . M1 . ... (the rightmost applies first)."""
    m = numpy.identity(4)
    for each in matrices:
        m = numpy.dot(m, each)
    return m


def is_same_transform(matrix0: Any, matrix1: Any) -> bool:
    """Whether two homogeneous matrices transform points the same way."""
    a = numpy.array(matrix0, dtype=numpy.float64)
    b = numpy.array(matrix1, dtype=numpy.float64)
    return bool(numpy.allclose(a / a[3, 3], b / b[3, 3]))


def _eigenvectors(m: numpy.ndarray, value: float, tolerance: float = 1e-8) -> numpy.ndarray:
    """Real eigenvectors of ``m`` (as columns) for eigenvalue ``value``."""
    w, v = numpy.linalg.eig(m)
    idx = numpy.where(abs(numpy.real(w) - value) < tolerance)[0]
    return numpy.real(v[:, idx])


def _fixed_point(m33: numpy.ndarray, t: numpy.ndarray) -> numpy.ndarray:
    """A point x with m33 x + t = x (the one nearest the origin), homogeneous."""
    x = numpy.linalg.lstsq(numpy.identity(3) - m33, t, rcond=None)[0]
    return numpy.append(x, 1.0)


# ----------------------------------------------------------------------------- reflection

def reflection_matrix(point: Sequence[float], normal: Sequence[float]) -> numpy.ndarray:
    """Mirror at the plane through ``point`` with ``normal``."""
    n = unit_vector(_vec(normal, 3))
    m = numpy.identity(4)
    m[:3, :3] -= 2.0 * numpy.outer(n, n)
    m[:3, 3] = (2.0 * numpy.dot(_vec(point, 3), n)) * n
    return m


def reflection_from_matrix(matrix: Any) -> Tuple[numpy.ndarray, numpy.ndarray]:
    """(point, normal) of the mirror plane of a reflection matrix."""
    m = numpy.array(matrix, dtype=numpy.float64)
    normals = _eigenvectors(m[:3, :3], -1.0)
    if not normals.shape[1]:
        raise ValueError("no unit eigenvector corresponding to eigenvalue -1")
    normal = normals[:, 0]
    normal = normal / vector_norm(normal)
    # the translation is 2 (p.n) n: half of it is the plane's point nearest the origin
    point = numpy.append(0.5 * m[:3, 3], 1.0)
    return point, normal


# ----------------------------------------------------------------------------- rotation

def rotation_matrix(angle: float, direction: Sequence[float],
                    point: Optional[Sequence[float]] = None) -> numpy.ndarray:
    """Rotation by ``angle`` about the axis along ``direction`` (through ``point``)."""
    s, c = math.sin(angle), math.cos(angle)
    d = unit_vector(_vec(direction, 3))
    # Rodrigues: cos I + (1 - cos) d d^T + sin [d]x
    r = c * numpy.identity(3) + (1.0 - c) * numpy.outer(d, d)
    r += s * numpy.array(((0.0, -d[2], d[1]), (d[2], 0.0, -d[0]), (-d[1], d[0], 0.0)))
    m = numpy.identity(4)
    m[:3, :3] = r
    if point is not None:
        p = _vec(point, 3)
        m[:3, 3] = p - numpy.dot(r, p)
    return m


def rotation_from_matrix(matrix: Any) -> Tuple[float, numpy.ndarray, numpy.ndarray]:
    """(angle, direction, point) of a rotation matrix."""
    m = numpy.array(matrix, dtype=numpy.float64)
    r = m[:3, :3]
    axes = _eigenvectors(r, 1.0)
    if not axes.shape[1]:
        raise ValueError("no unit eigenvector corresponding to eigenvalue 1")
    direction = axes[:, -1]
    direction = direction / vector_norm(direction)
    cosa = (numpy.trace(r) - 1.0) / 2.0
    # the antisymmetric part of R is sin(angle) [d]x
    skew = numpy.array((r[2, 1] - r[1, 2], r[0, 2] - r[2, 0], r[1, 0] - r[0, 1]))
    sina = numpy.dot(skew, direction) / 2.0
    angle = math.atan2(sina, cosa)
    point = _fixed_point(r, m[:3, 3])
    return angle, direction, point


# ----------------------------------------------------------------------------- scaling

def scale_matrix(factor: float, origin: Optional[Sequence[float]] = None,
                 direction: Optional[Sequence[float]] = None) -> numpy.ndarray:
    """Scale by ``factor`` about ``origin``, in all directions or along ``direction``."""
    m = numpy.identity(4)
    if direction is None:
        m[:3, :3] *= factor
        if origin is not None:
            m[:3, 3] = (1.0 - factor) * _vec(origin, 3)
    else:
        d = unit_vector(_vec(direction, 3))
        shrink = 1.0 - factor
        m[:3, :3] -= shrink * numpy.outer(d, d)
        if origin is not None:
            m[:3, 3] = (shrink * numpy.dot(_vec(origin, 3), d)) * d
    return m


def scale_from_matrix(matrix: Any) -> Tuple[float, numpy.ndarray, Optional[numpy.ndarray]]:
    """(factor, origin, direction) of a scaling matrix; direction None when uniform."""
    m = numpy.array(matrix, dtype=numpy.float64)
    m33 = m[:3, :3]
    factor = numpy.trace(m33) - 2.0  # a scaling along one direction has eigenvalues 1, 1, f
    candidates = _eigenvectors(m33, factor)
    if candidates.shape[1]:
        direction = candidates[:, 0]
        direction = direction / vector_norm(direction)
    else:
        factor = (factor + 2.0) / 3.0
        direction = None
    if not _eigenvectors(m, 1.0).shape[1]:
        raise ValueError("no eigenvector corresponding to eigenvalue 1")
    return factor, _fixed_point(m33, m[:3, 3]), direction


# ----------------------------------------------------------------------------- projection

def projection_matrix(point: Sequence[float], normal: Sequence[float],
                      direction: Optional[Sequence[float]] = None,
                      perspective: Optional[Sequence[float]] = None,
                      pseudo: bool = False) -> numpy.ndarray:
    """Projection onto the plane through ``point`` with ``normal``: orthogonal, parallel
    along ``direction``, or central from the eye point ``perspective``. A pseudo-perspective
    keeps relative depth: perspective = orthogonal . pseudo-perspective."""
    m = numpy.identity(4)
    p = _vec(point, 3)
    n = unit_vector(_vec(normal, 3))
    if perspective is not None:
        # x -> e + (x - e) ((p - e).n) / ((x - e).n), written with w = (e - x).n
        e = _vec(perspective, 3)
        m[:3, :3] = numpy.dot(e - p, n) * numpy.identity(3) - numpy.outer(e, n)
        if pseudo:
            m[:3, :3] -= numpy.outer(n, n)
            m[:3, 3] = numpy.dot(p, n) * (e + n)
        else:
            m[:3, 3] = numpy.dot(p, n) * e
        m[3, :3] = -n
        m[3, 3] = numpy.dot(e, n)
    elif direction is not None:
        # x -> x - d ((x - p).n) / (d.n)
        d = _vec(direction, 3)
        dn = numpy.dot(d, n)
        m[:3, :3] -= numpy.outer(d, n) / dn
        m[:3, 3] = d * (numpy.dot(p, n) / dn)
    else:
        m[:3, :3] -= numpy.outer(n, n)
        m[:3, 3] = numpy.dot(p, n) * n
    return m


def projection_from_matrix(matrix: Any, pseudo: bool = False) -> Tuple[Any, ...]:
    """(point, normal, direction, perspective, pseudo) for ``projection_matrix``."""
    m = numpy.array(matrix, dtype=numpy.float64)
    m33 = m[:3, :3]
    row = m[3, :3]
    if not pseudo and numpy.all(abs(row) < 1e-8):
        # parallel: m33 = I - d n^T / (d.n); d spans its null space, n that of its transpose
        u, _s, vh = numpy.linalg.svd(m33)
        if _s[-1] > 1e-8:
            raise ValueError("no eigenvector corresponding to eigenvalue 0")
        direction = vh[-1] / vector_norm(vh[-1])
        normal = u[:, -1] / vector_norm(u[:, -1])
        # the translation is d (p.n) / (d.n), whose component along n is p.n
        point = numpy.append(numpy.dot(m[:3, 3], normal) * normal, 1.0)
        return point, normal, direction, None, False
    # central: m = s [((e - p).n) I - e n^T (- n n^T), c (e (+ n)); -n^T, e.n] with c = p.n
    scale = vector_norm(row)
    if scale < 1e-12:
        raise ValueError("no eigenvector not corresponding to eigenvalue 0")
    n = -row / scale
    en = m[3, 3] / scale
    c = (2.0 * en - (1.0 if pseudo else 0.0) - numpy.trace(m33) / scale) / 3.0
    a = (en - c) * numpy.identity(3) - m33 / scale  # = e n^T (+ n n^T when pseudo)
    j = int(numpy.argmax(abs(n)))
    e = a[:, j] / n[j]
    if pseudo:
        e = e - n
    point = numpy.append(c * n, 1.0)
    return point, n, None, e, pseudo


def clip_matrix(left: float, right: float, bottom: float, top: float, near: float, far: float,
                perspective: bool = False) -> numpy.ndarray:
    """Map the box (or the view frustum along +z with the eye at the origin) to normalized
    device coordinates [-1, 1]^3; perspective results need dividing by w."""
    if left >= right or bottom >= top or near >= far:
        raise ValueError("invalid frustrum")
    width, height, depth = right - left, top - bottom, far - near
    if perspective:
        if near <= _EPS:
            raise ValueError("invalid frustrum: near <= 0")
        # w = -z: x/w runs from -1 at left to 1 at right on every depth plane
        return numpy.array((
            (-2.0 * near / width, 0.0, (right + left) / width, 0.0),
            (0.0, -2.0 * near / height, (top + bottom) / height, 0.0),
            (0.0, 0.0, -(far + near) / depth, 2.0 * near * far / depth),
            (0.0, 0.0, -1.0, 0.0)))
    return numpy.array((
        (2.0 / width, 0.0, 0.0, (right + left) / (left - right)),
        (0.0, 2.0 / height, 0.0, (top + bottom) / (bottom - top)),
        (0.0, 0.0, 2.0 / depth, (far + near) / (near - far)),
        (0.0, 0.0, 0.0, 1.0)))


# ----------------------------------------------------------------------------- shear

def shear_matrix(angle: float, direction: Sequence[float], point: Sequence[float],
                 normal: Sequence[float]) -> numpy.ndarray:
    """Shear by ``angle`` along ``direction`` on the plane through ``point`` with ``normal``
    (direction must lie in the plane)."""
    n = unit_vector(_vec(normal, 3))
    d = unit_vector(_vec(direction, 3))
    if abs(numpy.dot(n, d)) > 1e-6:
        raise ValueError("direction and normal vectors are not orthogonal")
    t = math.tan(angle)
    m = numpy.identity(4)
    m[:3, :3] += t * numpy.outer(d, n)
    m[:3, 3] = -t * numpy.dot(_vec(point, 3), n) * d
    return m


def shear_from_matrix(matrix: Any) -> Tuple[Any, ...]:
    """(angle, direction, point, normal) of a shear matrix."""
    m = numpy.array(matrix, dtype=numpy.float64)
    # m33 - I = tan(angle) d n^T has rank one
    u, s, vh = numpy.linalg.svd(m[:3, :3] - numpy.identity(3))
    if s[1] > 1e-4 * max(1.0, s[0]):
        raise ValueError(f"No two linear independent eigenvectors found {s}")
    direction, normal = u[:, 0], vh[0]
    tangent = s[0]
    angle = math.atan(tangent)
    if tangent > 1e-12:
        point = numpy.append(-numpy.dot(m[:3, 3], direction) / tangent * normal, 1.0)
    else:
        point = numpy.array((0.0, 0.0, 0.0, 1.0))
    return angle, direction, point, normal


# ----------------------------------------------------------------------------- decomposition

def decompose_matrix(matrix: Any) -> Tuple[Any, ...]:
    """(scale, shear, angles, translate, perspective) with
    matrix = perspective . translate . rotate('sxyz' angles) . shear . scale.

    shear is (xy, xz, yz) of the unit upper triangular shear; raises ValueError for a
    matrix with M[3, 3] = 0 or a singular linear part.
    """
    m = numpy.array(matrix, dtype=numpy.float64)
    if abs(m[3, 3]) < _EPS:
        raise ValueError("M[3, 3] is zero")
    m = m / m[3, 3]
    affine = m.copy()
    affine[3, :] = 0.0, 0.0, 0.0, 1.0
    if not numpy.linalg.det(affine):
        raise ValueError("Matrix is singular")
    if numpy.any(abs(m[3, :3]) > _EPS):
        perspective = numpy.dot(m[3, :], numpy.linalg.inv(affine))
    else:
        perspective = numpy.array((0.0, 0.0, 0.0, 1.0))
    translate = m[:3, 3].copy()
    # linear part = Q U: Q orthonormal, U = shear . scale upper triangular (Gram-Schmidt)
    q, u = numpy.linalg.qr(m[:3, :3])
    signs = numpy.sign(numpy.diag(u))
    signs[signs == 0] = 1.0
    q = q * signs
    u = (u.T * signs).T
    if numpy.linalg.det(q) < 0:  # a reflection: carried by negative scales
        q, u = -q, -u
    scale = numpy.diag(u).copy()
    shear = [u[0, 1] / u[1, 1], u[0, 2] / u[2, 2], u[1, 2] / u[2, 2]]
    angles = list(euler_from_matrix(q, "sxyz"))
    return scale, shear, angles, translate, perspective


def compose_matrix(scale: Any = None, shear: Any = None, angles: Any = None,
                   translate: Any = None, perspective: Any = None) -> numpy.ndarray:
    """The inverse of ``decompose_matrix``."""
    m = numpy.identity(4)
    if perspective is not None:
        p = numpy.identity(4)
        p[3, :] = _vec(perspective, 4)
        m = numpy.dot(m, p)
    if translate is not None:
        m = numpy.dot(m, translation_matrix(translate))
    if angles is not None:
        m = numpy.dot(m, euler_matrix(angles[0], angles[1], angles[2], "sxyz"))
    if shear is not None:
        z = numpy.identity(4)
        z[0, 1], z[0, 2], z[1, 2] = shear[0], shear[1], shear[2]
        m = numpy.dot(m, z)
    if scale is not None:
        m = numpy.dot(m, numpy.diag((scale[0], scale[1], scale[2], 1.0)))
    return m / m[3, 3]


def orthogonalization_matrix(lengths: Sequence[float], angles: Sequence[float]) -> numpy.ndarray:
    """Cartesian coordinates of a crystallographic cell (a, b, c; alpha, beta, gamma in
    degrees): c along z, b in the y-z plane."""
    a, b, c = lengths
    alpha, beta, gamma = (math.radians(v) for v in angles)
    sa, sb = math.sin(alpha), math.sin(beta)
    ca, cb, cg = math.cos(alpha), math.cos(beta), math.cos(gamma)
    co = (ca * cb - cg) / (sa * sb)  # cosine of the reciprocal angle gamma*
    return numpy.array((
        (a * sb * math.sqrt(1.0 - co * co), 0.0, 0.0, 0.0),
        (-a * sb * co, b * sa, 0.0, 0.0),
        (a * cb, b * ca, c, 0.0),
        (0.0, 0.0, 0.0, 1.0)))


def superimposition_matrix(v0: Any, v1: Any, scaling: bool = False,
                           usesvd: bool = True) -> numpy.ndarray:
    """The rigid (optionally uniformly scaled) transform taking point set v0 onto v1 in the
    least-squares sense; v0, v1 are (3, N) or (4, N) arrays with N >= 3. ``usesvd`` picks
    Kabsch's SVD solution, otherwise Horn's quaternion solution (the same optimum)."""
    a = numpy.array(v0, dtype=numpy.float64)[:3]
    b = numpy.array(v1, dtype=numpy.float64)[:3]
    if a.shape != b.shape or a.ndim != 2 or a.shape[1] < 3:
        raise ValueError("Vector sets are of wrong shape or type.")
    ca, cb = a.mean(axis=1), b.mean(axis=1)
    a = a - ca[:, None]
    b = b - cb[:, None]
    h = numpy.dot(b, a.T)  # cross-covariance
    m = numpy.identity(4)
    if usesvd:
        u, _s, vh = numpy.linalg.svd(h)
        d = numpy.sign(numpy.linalg.det(numpy.dot(u, vh))) or 1.0
        m[:3, :3] = numpy.dot(u * (1.0, 1.0, d), vh)
    else:
        s = h.T  # s[i, j] = sum a_i b_j
        sxx, sxy, sxz = s[0]
        syx, syy, syz = s[1]
        szx, szy, szz = s[2]
        n = numpy.array((
            (sxx + syy + szz, syz - szy, szx - sxz, sxy - syx),
            (syz - szy, sxx - syy - szz, sxy + syx, szx + sxz),
            (szx - sxz, sxy + syx, -sxx + syy - szz, syz + szy),
            (sxy - syx, szx + sxz, syz + szy, -sxx - syy + szz)))
        w, v = numpy.linalg.eigh(n)
        q = v[:, numpy.argmax(w)]  # (w, x, y, z) of the best rotation
        m = quaternion_matrix((q[1], q[2], q[3], q[0]))
    if scaling:
        m[:3, :3] *= math.sqrt(numpy.sum(b * b) / numpy.sum(a * a))
    m[:3, 3] = cb - numpy.dot(m[:3, :3], ca)
    return m


# ----------------------------------------------------------------------------- Euler angles

def _euler_quaternion(ai: float, aj: float, ak: float, axes: Any) -> Tuple[float, float, float, float]:
    i, j, k, parity, repetition, frame = _axes(axes)
    if frame:  # rotating frame: the static sequence in reverse order
        ai, ak = ak, ai
    # q = q_last(ak) q_mid(aj) q_first(ai), each q_axis(a) = (sin(a/2) e_axis, cos(a/2))
    first = [0.0, 0.0, 0.0, math.cos(ai / 2.0)]
    first[i] = math.sin(ai / 2.0)
    middle = [0.0, 0.0, 0.0, math.cos(aj / 2.0)]
    middle[j] = math.sin(aj / 2.0)
    last = [0.0, 0.0, 0.0, math.cos(ak / 2.0)]
    last[i if repetition else k] = math.sin(ak / 2.0)
    return _qmul(_qmul(last, middle), first)


def _qmul(a: Sequence[float], b: Sequence[float]) -> Tuple[float, float, float, float]:
    """Hamilton product a b of [x, y, z, w] quaternions."""
    ax, ay, az, aw = a[0], a[1], a[2], a[3]
    bx, by, bz, bw = b[0], b[1], b[2], b[3]
    return (aw * bx + ax * bw + ay * bz - az * by,
            aw * by + ay * bw + az * bx - ax * bz,
            aw * bz + az * bw + ax * by - ay * bx,
            aw * bw - ax * bx - ay * by - az * bz)


def quaternion_from_euler(ai: float, aj: float, ak: float, axes: Any = "sxyz") -> numpy.ndarray:
    """Quaternion [x, y, z, w] of Euler angles (radians) about ``axes``."""
    return numpy.array(_euler_quaternion(float(ai), float(aj), float(ak), axes))


def euler_matrix(ai: float, aj: float, ak: float, axes: Any = "sxyz") -> numpy.ndarray:
    """Rotation matrix of Euler angles (radians) about ``axes``."""
    return quaternion_matrix(_euler_quaternion(float(ai), float(aj), float(ak), axes))


def _euler_from_rows(m: Any, axes: Any) -> Tuple[float, float, float]:
    """Shoemake's extraction from a 3x3 rotation given as nested sequences."""
    i, j, k, parity, repetition, frame = _axes(axes)
    if repetition:  # R = R_i(c) R_j(b) R_i(a)
        sy = math.sqrt(m[i][j] * m[i][j] + m[i][k] * m[i][k])
        if sy > _EPS:
            a = math.atan2(m[i][j], m[i][k])
            b = math.atan2(sy, m[i][i])
            c = math.atan2(m[j][i], -m[k][i])
        else:  # gimbal lock: put the whole turn into the first angle
            a = math.atan2(-m[j][k], m[j][j])
            b = math.atan2(sy, m[i][i])
            c = 0.0
    else:  # R = R_k(c) R_j(b) R_i(a)
        cy = math.sqrt(m[i][i] * m[i][i] + m[j][i] * m[j][i])
        if cy > _EPS:
            a = math.atan2(m[k][j], m[k][k])
            b = math.atan2(-m[k][i], cy)
            c = math.atan2(m[j][i], m[i][i])
        else:
            a = math.atan2(-m[j][k], m[j][j])
            b = math.atan2(-m[k][i], cy)
            c = 0.0
    if parity:  # an odd axis order is the even one seen in a mirror: angles change sign
        a, b, c = -a, -b, -c
    if frame:
        a, c = c, a
    return a, b, c


def euler_from_matrix(matrix: Any, axes: Any = "sxyz") -> Tuple[float, float, float]:
    """Euler angles (radians) about ``axes`` of a rotation matrix (3x3 or 4x4); the middle
    angle is in [-pi/2, pi/2] (or [0, pi] for repeated axes)."""
    m = numpy.array(matrix, dtype=numpy.float64)[:3, :3].tolist()
    return _euler_from_rows(m, axes)


def euler_from_quaternion(quaternion: Sequence[float], axes: Any = "sxyz") -> Tuple[float, float, float]:
    """Euler angles (radians) about ``axes`` of a quaternion [x, y, z, w]."""
    return _euler_from_rows(_rows(quaternion), axes)


# ----------------------------------------------------------------------------- quaternions

def _rows(quaternion: Sequence[float]) -> list:
    """3x3 rotation (nested lists) of a quaternion, normalised on the way.

    The entries are 1 - 2(y^2 + z^2), 2(xy - zw), ... computed from q scaled by sqrt(2/|q|^2),
    in the order ROS's module rounds them: angles read from exact zeros (atan2's branch cut
    at +-pi) then come out with the same sign.
    """
    x, y, z, w = (float(quaternion[0]), float(quaternion[1]), float(quaternion[2]),
                  float(quaternion[3]))
    n = x * x + y * y + z * z + w * w
    if n < _EPS:
        return [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]]
    s = math.sqrt(2.0 / n)
    x, y, z, w = x * s, y * s, z * s, w * s
    xx, yy, zz = x * x, y * y, z * z
    xy, xz, yz = x * y, x * z, y * z
    xw, yw, zw = x * w, y * w, z * w
    return [[1.0 - yy - zz, xy - zw, xz + yw],
            [xy + zw, 1.0 - xx - zz, yz - xw],
            [xz - yw, yz + xw, 1.0 - xx - yy]]


def quaternion_matrix(quaternion: Sequence[float]) -> numpy.ndarray:
    """Homogeneous rotation matrix of a quaternion [x, y, z, w] (normalised first)."""
    m = numpy.identity(4)
    m[:3, :3] = _rows(quaternion)
    return m


def quaternion_from_matrix(matrix: Any) -> numpy.ndarray:
    """Unit quaternion [x, y, z, w] of a rotation matrix (3x3 or homogeneous 4x4).

    Sign: w > 0 when the rotation's trace is positive, otherwise the component of the
    largest diagonal entry is positive (Shepperd's method, as ROS's module chooses).
    """
    m = numpy.array(matrix, dtype=numpy.float64)
    w4 = m[3, 3] if m.shape[0] > 3 else 1.0
    r = m[:3, :3]
    trace = r[0, 0] + r[1, 1] + r[2, 2]
    q = numpy.empty(4)
    if trace > 0.0:
        t = trace + w4
        q[3] = t
        q[0] = r[2, 1] - r[1, 2]
        q[1] = r[0, 2] - r[2, 0]
        q[2] = r[1, 0] - r[0, 1]
    else:
        i = 0
        if r[1, 1] > r[0, 0]:
            i = 1
        if r[2, 2] > r[i, i]:
            i = 2
        j, k = (i + 1) % 3, (i + 2) % 3
        t = r[i, i] - (r[j, j] + r[k, k]) + w4
        q[i] = t
        q[j] = r[i, j] + r[j, i]
        q[k] = r[k, i] + r[i, k]
        q[3] = r[k, j] - r[j, k]
    return q * (0.5 / math.sqrt(t * w4))


def quaternion_about_axis(angle: float, axis: Sequence[float]) -> numpy.ndarray:
    """Quaternion of a rotation by ``angle`` about ``axis``."""
    q = numpy.zeros(4)
    q[:3] = _vec(axis, 3)
    length = vector_norm(q)
    if length > _EPS:
        q *= math.sin(angle / 2.0) / length
    q[3] = math.cos(angle / 2.0)
    return q


def quaternion_multiply(quaternion1: Sequence[float], quaternion0: Sequence[float]) -> numpy.ndarray:
    """The product quaternion1 * quaternion0 (quaternion0 applies first)."""
    return numpy.array(_qmul(quaternion1, quaternion0), dtype=numpy.float64)


def quaternion_conjugate(quaternion: Sequence[float]) -> numpy.ndarray:
    """[-x, -y, -z, w]."""
    return numpy.array((-quaternion[0], -quaternion[1], -quaternion[2], quaternion[3]),
                       dtype=numpy.float64)


def quaternion_inverse(quaternion: Sequence[float]) -> numpy.ndarray:
    """The conjugate divided by the squared length."""
    q = numpy.array(quaternion, dtype=numpy.float64)
    return quaternion_conjugate(q) / numpy.dot(q, q)


def quaternion_slerp(quat0: Sequence[float], quat1: Sequence[float], fraction: float,
                     spin: int = 0, shortestpath: bool = True) -> numpy.ndarray:
    """Spherical linear interpolation from quat0 (fraction 0) to quat1 (fraction 1); ``spin``
    adds extra half turns, ``shortestpath`` flips quat1 when that is the shorter way."""
    q0 = unit_vector(_vec(quat0, 4))
    q1 = unit_vector(_vec(quat1, 4))
    if fraction == 0.0:
        return q0
    if fraction == 1.0:
        return q1
    d = float(numpy.dot(q0, q1))
    if abs(abs(d) - 1.0) < _EPS:
        return q0
    if shortestpath and d < 0.0:
        d = -d
        q1 = -q1
    angle = math.acos(d) + spin * math.pi
    if abs(angle) < _EPS:
        return q0
    inv = 1.0 / math.sin(angle)
    return q0 * (math.sin((1.0 - fraction) * angle) * inv) + q1 * (math.sin(fraction * angle) * inv)


def random_quaternion(rand: Optional[Sequence[float]] = None) -> numpy.ndarray:
    """A uniformly distributed unit quaternion; ``rand`` gives the three uniform [0, 1)
    numbers to use (Shoemake's subgroup algorithm)."""
    if rand is None:
        rand = numpy.random.rand(3)
    else:
        assert len(rand) == 3
    r1, r2 = math.sqrt(1.0 - rand[0]), math.sqrt(rand[0])
    t1, t2 = 2.0 * math.pi * rand[1], 2.0 * math.pi * rand[2]
    return numpy.array((math.sin(t1) * r1, math.cos(t1) * r1, math.sin(t2) * r2, math.cos(t2) * r2))


def random_rotation_matrix(rand: Optional[Sequence[float]] = None) -> numpy.ndarray:
    """A uniformly distributed rotation matrix (see ``random_quaternion``)."""
    return quaternion_matrix(random_quaternion(rand))


# ----------------------------------------------------------------------------- arcball

def arcball_map_to_sphere(point: Sequence[float], center: Sequence[float],
                          radius: float) -> numpy.ndarray:
    """Window coordinates (y down) to a point on the unit sphere (its rim when outside)."""
    v = numpy.array(((point[0] - center[0]) / radius, (center[1] - point[1]) / radius, 0.0))
    n = v[0] * v[0] + v[1] * v[1]
    if n > 1.0:
        v /= math.sqrt(n)
    else:
        v[2] = math.sqrt(1.0 - n)
    return v


def arcball_constrain_to_axis(point: Sequence[float], axis: Sequence[float]) -> numpy.ndarray:
    """The sphere point nearest ``point`` on the great circle perpendicular to ``axis``."""
    v = numpy.array(point, dtype=numpy.float64)
    a = numpy.array(axis, dtype=numpy.float64)
    v -= a * numpy.dot(a, v)
    n = vector_norm(v)
    if n > _EPS:
        if v[2] < 0.0:
            v = -v
        return v / n
    if a[2] == 1.0:
        return numpy.array((1.0, 0.0, 0.0))
    return unit_vector([-a[1], a[0], 0.0])


def arcball_nearest_axis(point: Sequence[float], axes: Sequence[Sequence[float]]) -> Any:
    """The axis whose constraint circle passes nearest ``point``."""
    p = numpy.array(point, dtype=numpy.float64)
    nearest, best = None, -1.0
    for axis in axes:
        t = numpy.dot(arcball_constrain_to_axis(p, axis), p)
        if t > best:
            nearest, best = axis, t
    return nearest


class Arcball:
    """Shoemake's virtual trackball: drag on a window to rotate, optionally about axes."""

    def __init__(self, initial: Any = None) -> None:
        """``initial``: a quaternion or a rotation matrix."""
        self._axis = None
        self._axes = None
        self._radius = 1.0
        self._center = [0.0, 0.0]
        self._vdown = numpy.array((0.0, 0.0, 1.0))
        self._constrain = False
        if initial is None:
            self._qdown = numpy.array((0.0, 0.0, 0.0, 1.0))
        else:
            initial = numpy.array(initial, dtype=numpy.float64)
            if initial.shape == (4, 4):
                self._qdown = quaternion_from_matrix(initial)
            elif initial.shape == (4,):
                self._qdown = initial / vector_norm(initial)
            else:
                raise ValueError("initial not a quaternion or matrix.")
        self._qnow = self._qpre = self._qdown

    def place(self, center: Sequence[float], radius: float) -> None:
        """Where the ball is on the window (after a resize)."""
        self._radius = float(radius)
        self._center[0], self._center[1] = center[0], center[1]

    def setaxes(self, *axes: Sequence[float]) -> None:
        """Axes to constrain rotations to."""
        self._axes = None if axes is None else [unit_vector(axis) for axis in axes]

    def setconstrain(self, constrain: bool) -> None:
        self._constrain = constrain == True  # noqa: E712 (a truthy non-bool is not "on")

    def getconstrain(self) -> bool:
        return self._constrain

    def down(self, point: Sequence[float]) -> None:
        """Mouse button pressed at window coordinates ``point``."""
        self._vdown = arcball_map_to_sphere(point, self._center, self._radius)
        self._qdown = self._qpre = self._qnow
        if self._constrain and self._axes is not None:
            self._axis = arcball_nearest_axis(self._vdown, self._axes)
            self._vdown = arcball_constrain_to_axis(self._vdown, self._axis)
        else:
            self._axis = None

    def drag(self, point: Sequence[float]) -> None:
        """Mouse moved to window coordinates ``point`` with the button held."""
        vnow = arcball_map_to_sphere(point, self._center, self._radius)
        if self._axis is not None:
            vnow = arcball_constrain_to_axis(vnow, self._axis)
        self._qpre = self._qnow
        t = numpy.cross(self._vdown, vnow)
        if numpy.dot(t, t) < _EPS:
            self._qnow = self._qdown
        else:
            # the rotation taking vdown to vnow (twice their angle, as arcballs do)
            q = (t[0], t[1], t[2], numpy.dot(self._vdown, vnow))
            self._qnow = quaternion_multiply(q, self._qdown)

    def next(self, acceleration: float = 0.0) -> None:
        """Keep rotating the way the last drag went."""
        q = quaternion_slerp(self._qpre, self._qnow, 2.0 + acceleration, False)
        self._qpre, self._qnow = self._qnow, q

    def matrix(self) -> numpy.ndarray:
        """The current rotation as a homogeneous matrix."""
        return quaternion_matrix(self._qnow)
