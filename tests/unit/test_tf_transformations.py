"""tf.transformations: ROS's conventions ([x, y, z, w], 'sxyz' axes), checked on their own and
against Debian's python3-tf on random inputs (hypothesis, through a /usr/bin/python3 oracle)."""

from __future__ import annotations

import math

import numpy
import pytest
from hypothesis import HealthCheck, assume, example, given, settings
from hypothesis import strategies as st

import tf
from minros.tf import transformations as own
from minros.tf.testing import OracleError
from tf import transformations as T

AXES = sorted(T._AXES2TUPLE)


def close(a, b, tol=1e-9):
    a, b = numpy.asarray(a, dtype=float), numpy.asarray(b, dtype=float)
    return a.shape == b.shape and numpy.allclose(a, b, rtol=0, atol=tol)


# --------------------------------------------------------------------------- conventions

def test_quaternions_are_xyzw_and_axes_follow_ros():
    assert numpy.allclose(T.quaternion_from_euler(1, 2, 3, "ryxz"),
                          [0.310622, -0.718287, 0.444435, 0.435953], atol=1e-6)
    assert numpy.allclose(T.quaternion_about_axis(0.123, (1, 0, 0)),
                          [0.06146124, 0, 0, 0.99810947], atol=1e-8)
    assert numpy.allclose(T.euler_from_quaternion([0.06146124, 0, 0, 0.99810947]),
                          [0.123, 0, 0], atol=1e-7)
    # yaw about z by 90 degrees, the default static x-y-z order (roll, pitch, yaw)
    q = T.quaternion_from_euler(0, 0, math.pi / 2)
    assert numpy.allclose(q, [0, 0, math.sqrt(0.5), math.sqrt(0.5)])
    assert numpy.allclose(T.quaternion_matrix(q)[:3, :3] @ [1, 0, 0], [0, 1, 0])
    # static xyz equals rotating zyx with the angles reversed, and the tuple form works
    assert numpy.allclose(T.euler_matrix(0.1, 0.2, 0.3, "sxyz"), T.euler_matrix(0.3, 0.2, 0.1, "rzyx"))
    assert numpy.allclose(T.euler_matrix(1, 2, 3, (0, 1, 0, 1)), T.euler_matrix(1, 2, 3, "ryzx"))
    assert numpy.allclose(numpy.sum(T.euler_matrix(1, 2, 3, "syxz")[0]), -1.34786452)
    assert numpy.allclose(T.quaternion_multiply([1, -2, 3, 4], [-5, 6, 7, 8]), [-44, -14, 48, 28])
    with pytest.raises(KeyError, match="unknown Euler axes"):
        T.euler_matrix(1, 2, 3, "xyz")


def test_matrices_from_the_module_documentation():
    R = T.rotation_matrix(0.123, (1, 2, 3))
    assert numpy.allclose(T.quaternion_from_matrix(R), [0.0164262, 0.0328524, 0.0492786, 0.9981095])
    assert numpy.allclose(numpy.sum(T.orthogonalization_matrix([9.8, 12.0, 15.5], [87.2, 80.7, 69.7])),
                          43.063229)
    frustum = (0.1, 0.5, 0.2, 0.9, 0.3, 1.7)
    m = T.clip_matrix(*frustum)
    assert numpy.allclose(m @ [0.1, 0.2, 0.3, 1], [-1, -1, -1, 1])
    v = T.clip_matrix(*frustum, perspective=True) @ [0.5, 0.9, 0.3, 1]
    assert numpy.allclose(v / v[3], [1, 1, -1, 1])
    ball = T.Arcball()
    ball.place([320, 320], 320)
    ball.down([500, 250])
    ball.drag([475, 275])
    assert numpy.allclose(numpy.sum(ball.matrix()), 3.90583455)
    ball = T.Arcball(initial=[0, 0, 0, 1])
    ball.place([320, 320], 320)
    ball.setaxes([1, 1, 0], [-1, 1, 0])
    ball.setconstrain(True)
    ball.down([400, 200])
    ball.drag([200, 400])
    assert numpy.allclose(numpy.sum(ball.matrix()), 0.2055924)
    ball.next()
    scale, shear, angles, trans, persp = T.decompose_matrix(T.scale_matrix(0.123))
    assert scale[0] == pytest.approx(0.123)
    assert T.vector_norm([]) == 0.0 and list(T.unit_vector([1.0])) == [1.0]
    assert T.is_same_transform(numpy.identity(4), numpy.identity(4))
    assert not T.is_same_transform(numpy.identity(4), T.random_rotation_matrix())
    # tf's own package exposes the module, as `import tf` does in ROS
    assert tf.transformations.euler_from_quaternion is T.euler_from_quaternion


def test_bad_input_raises_value_errors():
    with pytest.raises(ValueError, match="invalid frustrum"):
        T.clip_matrix(1, 0, 0, 1, 0, 1)
    with pytest.raises(ValueError, match="not orthogonal"):
        T.shear_matrix(0.3, (1, 0, 0), (0, 0, 0), (1, 0, 0))
    with pytest.raises(ValueError, match="singular"):
        T.decompose_matrix(numpy.zeros((4, 4)) + numpy.diag([0, 0, 0, 1]))
    with pytest.raises(ValueError, match="wrong shape"):
        T.superimposition_matrix(numpy.zeros((3, 2)), numpy.zeros((3, 2)))


# --------------------------------------------------------------------------- against Debian

finite = st.floats(-10, 10, allow_nan=False, allow_infinity=False)
angle = st.floats(-7, 7, allow_nan=False, allow_infinity=False)
unit_interval = st.floats(0, 1, exclude_max=True)
vec3 = st.tuples(finite, finite, finite)
# quaternions away from zero length (the functions treat |q| < eps as identity)
quat = st.tuples(finite, finite, finite, finite).filter(lambda q: sum(c * c for c in q) > 1e-3)
direction = vec3.filter(lambda v: sum(c * c for c in v) > 1e-3)

SETTINGS = settings(max_examples=150, deadline=None,
                    suppress_health_check=[HealthCheck.function_scoped_fixture])


def _not_gimbal_locked(q, axes):
    """Away from the gimbal lock, where the split between the outer angles is a convention
    decided by rounding (both libraries agree on the rotation there, not on the split)."""
    i, j, k, parity, repetition, frame = own._axes(axes)
    m = T.quaternion_matrix(q)
    if repetition:
        return math.hypot(m[i, j], m[i, k]) > 1e-6
    return math.hypot(m[i, i], m[j, i]) > 1e-6


@SETTINGS
@given(a=angle, b=angle, c=angle, axes=st.sampled_from(AXES + [T._AXES2TUPLE["sxyz"], T._AXES2TUPLE["rzxz"]]))
def test_euler_to_quaternion_and_matrix_match_debian(tf_oracle, a, b, c, axes):
    sent = {"t": list(axes)} if isinstance(axes, tuple) else axes  # JSON has no tuples
    assert close(T.quaternion_from_euler(a, b, c, axes), tf_oracle.transformations("quaternion_from_euler", a, b, c, sent))
    assert close(T.euler_matrix(a, b, c, axes), tf_oracle.transformations("euler_matrix", a, b, c, sent))


@SETTINGS
@given(q=quat, axes=st.sampled_from(AXES))
def test_euler_from_quaternion_and_matrix_match_debian(tf_oracle, q, axes):
    assume(_not_gimbal_locked(q, axes))
    assert close(T.euler_from_quaternion(q, axes), tf_oracle.transformations("euler_from_quaternion", q, axes))
    m = T.quaternion_matrix(q)
    assert close(T.euler_from_matrix(m, axes), tf_oracle.transformations("euler_from_matrix", m, axes))


EPS = float(numpy.finfo(float).eps)


def slerp_tolerance(q0, q1, fraction, spin, shortest) -> float:
    """How far two faithful evaluations of ROS's quaternion_slerp may differ at these inputs.

    ROS's formula normalizes q0 and q1, takes d = q0.q1, angle = acos(d) + spin*pi and weights
    q0 and q1 by sin((1-f)*angle)/sin(angle) and sin(f*angle)/sin(angle). The norms are sums
    of four squares that numpy leaves to the BLAS: Debian's numpy (reference BLAS) adds them
    in order, a pip numpy's OpenBLAS with fused multiply-adds, and the two differ in the last
    bit for a quarter of all 4-vectors (on either Python). So each unit component carries a
    relative error of a few ulps, d an absolute one of about 10 ulps (16 here, with margin).
    acos amplifies that by 1/sqrt(1 - d^2) next to |d| = 1, and the weights by their
    derivatives in the angle, which grow as 1/sin(angle)^2 when spin turns a tiny angle into
    one near pi. Where the inputs fix no digit of the answer at all, the tolerance is infinite.
    """
    eta = 16 * EPS
    u0 = numpy.asarray(q0, dtype=float) / numpy.linalg.norm(q0)
    u1 = numpy.asarray(q1, dtype=float) / numpy.linalg.norm(q1)
    d = float(u0 @ u1)
    if shortest and d < 0.0:
        d = -d
    across = math.sqrt(max(1.0 - d * d, 0.0))
    if across < eta:  # |d| = 1 to rounding: ROS returns q0, and so does the neighbourhood
        return 1e-7
    angle = math.acos(d) + spin * math.pi
    d_angle = eta / across + eta * abs(angle)  # through acos, and the addition of spin*pi
    sin_a, cos_a = math.sin(angle), math.cos(angle)
    if abs(sin_a) <= 2 * d_angle:
        return math.inf
    bound = 0.0
    for g in (1.0 - fraction, fraction):
        weight = math.sin(g * angle) / sin_a
        slope = (g * math.cos(g * angle) * sin_a - math.sin(g * angle) * cos_a) / sin_a ** 2
        bound += abs(slope) * d_angle + eta * abs(weight)
    return 1e-7 + bound


def test_slerp_tolerance_is_tight_where_the_inputs_decide():
    # well conditioned: ROS's 1e-7 is what is asked
    assert slerp_tolerance((0, 0, 0, 1), (0, 0, 1, 1), 0.5, 0, True) < 1.0000001e-7
    # the CI failure below: spin 1 through a 2e-6 rad angle; w is about -888391 there and
    # its last 3-4 digits are rounding
    tol = slerp_tolerance((0, 0, 0, 1), (0, 1e-5, 1e-5, 6.2818), 0.5, 1, False)
    assert 39 < tol < 1000  # 39: what two ulps of the norm change (summation order, seen)


@SETTINGS
@given(q0=quat, q1=quat, fraction=st.floats(-1, 2), spin=st.integers(-1, 1), shortest=st.booleans())
# found on CPython 3.13 in CI: -0.7071112 against ROS's -0.7071267 (the norm's last bit)
@example(q0=(0.0, 0.0, 0.0, 1.0), q1=(0.0, 1e-5, 1e-5, 6.2818), fraction=0.5, spin=1,
         shortest=False)
# the same on this project's 2-CPU machine, on every Python: the norm of q1 is 1 ulp apart
# between a pip numpy (OpenBLAS, FMA) and Debian's (reference BLAS), w 326452.7 vs 326451.7
@example(q0=(0.0, 0.0, 0.0, 1.0), q1=(0.0, 1.1e-5, 1.1e-5, 2.5392), fraction=0.5, spin=1,
         shortest=False)
def test_quaternion_algebra_matches_debian(tf_oracle, q0, q1, fraction, spin, shortest):
    assert close(T.quaternion_matrix(q0), tf_oracle.transformations("quaternion_matrix", q0))
    m = T.quaternion_matrix(q0)
    assert close(T.quaternion_from_matrix(m), tf_oracle.transformations("quaternion_from_matrix", m))
    assert close(T.quaternion_multiply(q0, q1), tf_oracle.transformations("quaternion_multiply", q0, q1))
    assert close(T.quaternion_inverse(q0), tf_oracle.transformations("quaternion_inverse", q0))
    assert close(T.quaternion_conjugate(q0), tf_oracle.transformations("quaternion_conjugate", q0))
    ours = T.quaternion_slerp(q0, q1, fraction, spin, shortest)
    ros = tf_oracle.transformations("quaternion_slerp", q0, q1, fraction, spin, shortest)
    tol = slerp_tolerance(q0, q1, fraction, spin, shortest)
    if math.isinf(tol):  # rounding decides every digit: the same kind of answer, no more
        assert numpy.shape(ours) == numpy.shape(ros)
    else:
        assert close(ours, ros, tol)


@SETTINGS
@given(a=angle, axis=direction, point=vec3, factor=st.floats(-5, 5).filter(lambda f: abs(f) > 1e-2),
       eye=vec3, u=st.tuples(unit_interval, unit_interval, unit_interval))
def test_matrix_constructors_match_debian(tf_oracle, a, axis, point, factor, eye, u):
    assert close(T.quaternion_about_axis(a, axis), tf_oracle.transformations("quaternion_about_axis", a, axis))
    assert close(T.random_quaternion(u), tf_oracle.transformations("random_quaternion", u))
    assert close(T.rotation_matrix(a, axis, point), tf_oracle.transformations("rotation_matrix", a, axis, point), 1e-8)
    assert close(T.reflection_matrix(point, axis), tf_oracle.transformations("reflection_matrix", point, axis), 1e-8)
    assert close(T.scale_matrix(factor, point), tf_oracle.transformations("scale_matrix", factor, point), 1e-8)
    assert close(T.scale_matrix(factor, point, axis),
                 tf_oracle.transformations("scale_matrix", factor, point, axis), 1e-8)
    assert close(T.projection_matrix(point, axis), tf_oracle.transformations("projection_matrix", point, axis), 1e-8)
    if abs(numpy.dot(T.unit_vector(axis), eye)) > 1e-2:  # a direction not parallel to the plane
        assert close(T.projection_matrix(point, axis, eye),
                     tf_oracle.transformations("projection_matrix", point, axis, eye), 1e-7)
    for pseudo in (False, True):
        assert close(T.projection_matrix(point, axis, perspective=eye, pseudo=pseudo),
                     tf_oracle.transformations("projection_matrix", point, axis, perspective=eye,
                                            pseudo=pseudo), 1e-8)
    assert close(T.translation_matrix(point), tf_oracle.transformations("translation_matrix", point))


def same_up_to_scale(a, b):
    """Two homogeneous matrices that transform alike (also when M[3, 3] is 0)."""
    a, b = numpy.asarray(a, dtype=float), numpy.asarray(b, dtype=float)
    a = a / numpy.linalg.norm(a)
    b = b / numpy.linalg.norm(b)
    return numpy.allclose(a, b, atol=1e-7) or numpy.allclose(a, -b, atol=1e-7)


@SETTINGS
@given(a=st.floats(-3, 3).filter(lambda v: abs(v) > 1e-3), axis=direction, point=vec3,
       factor=st.floats(0.1, 5).filter(lambda f: abs(f - 1) > 1e-2), eye=vec3,
       other=direction)
def test_decompositions_rebuild_the_same_transform(tf_oracle, a, axis, point, factor, eye, other):
    """Where the answer is not unique (axis sign, a point on a line or plane) ours rebuilds
    the matrix; where a part of it is unique (a rotation's angle up to the axis sign, a scale
    factor) it equals Debian's."""
    rotation = T.rotation_matrix(a, axis, point)
    angle, direc, _ = T.rotation_from_matrix(rotation)
    assert T.is_same_transform(T.rotation_matrix(*T.rotation_from_matrix(rotation)), rotation)
    theirs = tf_oracle.transformations("rotation_from_matrix", rotation)
    assert abs(angle) == pytest.approx(abs(theirs[0]), abs=1e-7)
    assert numpy.allclose(numpy.abs(direc), numpy.abs(theirs[1]), atol=1e-7)
    mirror = T.reflection_matrix(point, axis)
    assert T.is_same_transform(T.reflection_matrix(*T.reflection_from_matrix(mirror)), mirror)
    for scaling in (T.scale_matrix(factor, point), T.scale_matrix(factor, point, axis)):
        ours = T.scale_from_matrix(scaling)
        assert T.is_same_transform(T.scale_matrix(*ours), scaling)
        assert ours[0] == pytest.approx(tf_oracle.transformations("scale_from_matrix", scaling)[0])
    normal = numpy.cross(axis, other)
    if numpy.linalg.norm(normal) > 1e-2:
        shear = T.shear_matrix(a / 3, axis, point, normal)
        assert T.is_same_transform(T.shear_matrix(*T.shear_from_matrix(shear)), shear)
    if abs(numpy.dot(T.unit_vector(axis), numpy.subtract(eye, point))) > 1e-1:
        for pseudo in (False, True):
            persp = T.projection_matrix(point, axis, perspective=eye, pseudo=pseudo)
            assert same_up_to_scale(T.projection_matrix(*T.projection_from_matrix(persp, pseudo)), persp)
    ortho = T.projection_matrix(point, axis)
    assert T.is_same_transform(T.projection_matrix(*T.projection_from_matrix(ortho)), ortho)
    if abs(numpy.dot(T.unit_vector(axis), T.unit_vector(other))) > 1e-1:
        parallel = T.projection_matrix(point, axis, other)
        assert T.is_same_transform(T.projection_matrix(*T.projection_from_matrix(parallel)), parallel)


@SETTINGS
@given(scale=st.tuples(*[st.floats(0.2, 3)] * 3), shear=st.tuples(*[st.floats(-0.5, 0.5)] * 3),
       angles=st.tuples(*[st.floats(-1.5, 1.5)] * 3), trans=vec3,
       persp=st.tuples(*[st.floats(-0.1, 0.1)] * 3))
def test_compose_and_decompose_match_debian(tf_oracle, scale, shear, angles, trans, persp):
    # compose_matrix divides by 1 + perspective . translation: near 0 (persp 0.1 with a translation
    # of -10), two correct implementations differ by rounding alone; compare where it is defined
    assume(abs(1.0 + numpy.dot(persp, trans)) > 0.2)
    p = list(persp) + [1.0]
    m = T.compose_matrix(scale, shear, angles, trans, p)
    assert close(m, tf_oracle.transformations("compose_matrix", scale, shear, angles, trans, p), 1e-9)
    ours = T.decompose_matrix(m)
    theirs = tf_oracle.transformations("decompose_matrix", m)
    for a, b in zip(ours, theirs):
        assert close(a, b, 1e-7)


@SETTINGS
@given(u=st.tuples(unit_interval, unit_interval, unit_interval), trans=vec3,
       scale=st.floats(0.5, 2), scaling=st.booleans(), usesvd=st.booleans(),
       seed=st.integers(0, 2 ** 16))
def test_superimposition_matches_debian(tf_oracle, u, trans, scale, scaling, usesvd, seed):
    rng = numpy.random.default_rng(seed)
    v0 = rng.normal(size=(3, 8)) * 3
    m = T.concatenate_matrices(T.translation_matrix(trans), T.random_rotation_matrix(u),
                               T.scale_matrix(scale))
    v1 = (m @ numpy.vstack([v0, numpy.ones(8)]))[:3] + rng.normal(size=(3, 8)) * 1e-3
    ours = T.superimposition_matrix(v0, v1, scaling, usesvd)
    assert close(ours, tf_oracle.transformations("superimposition_matrix", v0, v1, scaling, usesvd), 1e-7)


def test_errors_match_debian(tf_oracle):
    with pytest.raises(OracleError, match="ValueError: invalid frustrum"):
        tf_oracle.transformations("clip_matrix", 1, 0, 0, 1, 0, 1)
    with pytest.raises(ValueError, match="invalid frustrum"):
        T.clip_matrix(1, 0, 0, 1, 0, 1)
    with pytest.raises(OracleError, match="ValueError: direction and normal vectors are not orthogonal"):
        tf_oracle.transformations("shear_matrix", 0.3, (1, 0, 0), (0, 0, 0), (1, 0, 0))
