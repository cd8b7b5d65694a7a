"""PyKDL (minros.kdl) on its own: the algebra of frames, the kinematic family and the solvers
checked against mathematics (inverses, round trips, numerical derivatives, the equation of
motion), plus the Python contract (references, copies, pickling, errors).
Debian's numbers are compared in tests/interop/test_kdl_interop.py."""

from __future__ import annotations

import copy
import math
import pickle

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

import PyKDL as K

finite = st.floats(-10, 10, allow_nan=False, allow_infinity=False)
angle = st.floats(-math.pi, math.pi, allow_nan=False)
vectors = st.builds(K.Vector, finite, finite, finite)
unit_quaternions = st.tuples(*[st.floats(-1, 1)] * 4).filter(
    lambda q: sum(c * c for c in q) > 0.01).map(
    lambda q: tuple(c / math.sqrt(sum(x * x for x in q)) for c in q))
rotations = unit_quaternions.map(lambda q: K.Rotation.Quaternion(*q))
frames = st.builds(K.Frame, rotations, vectors)


def close(a, b, tol=1e-9) -> bool:
    return K.Equal(a, b, tol)


def matrix(f: K.Frame) -> np.ndarray:
    return np.array([[f[i, j] for j in range(4)] for i in range(3)] + [[0, 0, 0, 1]])


# ------------------------------------------------------------------------------- frames

@settings(max_examples=60, deadline=None)
@given(frames, frames, vectors)
def test_frames_compose_as_homogeneous_matrices(f, g, v):
    assert np.allclose(matrix(f * g), matrix(f) @ matrix(g))
    assert np.allclose(list(f * v), (matrix(f) @ [v[0], v[1], v[2], 1])[:3])
    assert close(f * f.Inverse(), K.Frame.Identity())
    assert close(f.Inverse(f * v), v)


@settings(max_examples=60, deadline=None)
@given(rotations)
def test_rotation_conversions_round_trip(r):
    assert close(K.Rotation.Quaternion(*r.GetQuaternion()), r)
    assert close(K.Rotation.RPY(*r.GetRPY()), r)
    assert close(K.Rotation.EulerZYX(*r.GetEulerZYX()), r)
    # KDL treats beta within 1e-12 (in cos) of 0 or pi as singular: ~1e-6 off there
    assert close(K.Rotation.EulerZYZ(*r.GetEulerZYZ()), r, 1e-5)
    angle_, axis = r.GetRotAngle()
    assert 0 <= angle_ <= math.pi
    assert close(K.Rotation.Rot(axis, angle_), r, 1e-6)
    assert close(K.Rotation.Rot(r.GetRot(), r.GetRot().Norm()), r, 1e-6)
    assert close(r * r.Inverse(), K.Rotation.Identity())


def test_quaternion_sign_and_singular_rotations_follow_kdl():
    # w >= 0 away from a half turn; at a half turn the largest diagonal decides
    assert K.Rotation.RotZ(3.0).GetQuaternion()[3] > 0
    x, y, z, w = K.Rotation.RotX(math.pi).GetQuaternion()
    assert (round(x, 12), round(w, 12)) == (1.0, 0.0)
    assert K.Rotation.Identity().GetRotAngle()[1] == K.Vector(0, 0, 1)
    assert K.Rotation.RPY(0.3, math.pi / 2, 0.2).GetRPY()[0] == 0.0  # gimbal lock: roll is 0
    # a zero axis is taken as x, as KDL does
    assert close(K.Rotation.Rot(K.Vector(), 1.0), K.Rotation.RotX(1.0))


@settings(max_examples=60, deadline=None)
@given(frames, frames, st.floats(0.1, 10))
def test_diff_and_add_delta_are_inverse(a, b, dt):
    t = K.diff(a, b, dt)
    assert close(K.addDelta(a, t, dt), b, 1e-6)
    assert close(K.diff(a.p, b.p, dt), t.vel)


def test_twist_and_wrench_transform_preserve_power():
    f = K.Frame(K.Rotation.RPY(0.3, -0.2, 1.1), K.Vector(0.4, -1.0, 2.0))
    t = K.Twist(K.Vector(1, 2, 3), K.Vector(-0.5, 0.2, 0.9))
    w = K.Wrench(K.Vector(3, -1, 2), K.Vector(0.3, 0.1, -0.4))
    assert math.isclose(K.dot(f * t, f * w), K.dot(t, w), rel_tol=1e-12)
    assert close(f.Inverse(f * t), t)
    assert close(f.Inverse(f * w), w)
    # a twist referred to another point: the velocity of that point
    moved = t.RefPoint(K.Vector(1, 0, 0))
    assert close(moved.vel, t.vel + t.rot * K.Vector(1, 0, 0))


def test_members_are_references_and_assignment_copies():
    f = K.Frame()
    f.p[2] += 0.5  # the frame's own Vector
    f.M.DoRotZ(0.3)
    assert f.p[2] == 0.5 and close(f.M, K.Rotation.RotZ(0.3))
    v = K.Vector(1, 2, 3)
    f.p = v  # copied in
    v[0] = 9
    assert f.p[0] == 1
    held = f.p
    f.p = K.Vector(7, 7, 7)
    assert held[0] == 7  # an earlier reference sees the assignment, as in PyKDL
    w = v
    v += K.Vector(1, 1, 1)  # in place, as PyKDL's __iadd__
    assert w is v and w[0] == 10


def test_equality_uses_kdl_epsilon_and_objects_are_unhashable():
    assert K.Vector(1, 2, 3) == K.Vector(1, 2, 3 + 1e-7)
    assert K.Vector(1, 2, 3) != K.Vector(1, 2, 3 + 1e-5)
    assert K.Equal(K.Vector(1, 2, 3), K.Vector(1, 2, 3.5), 1.0)
    assert K.Vector() != K.Twist() and not (K.Vector() == 5)
    with pytest.raises(TypeError):
        hash(K.Vector())


def test_copies_and_pickles_are_independent_and_exact():
    f = K.Frame(K.Rotation(1, 2, 3, 4, 5, 6, 7, 8, 9.5), K.Vector(1, 2, 3))
    for clone in (copy.copy(f), copy.deepcopy(f), pickle.loads(pickle.dumps(f)), K.Frame(f)):
        assert [clone[i, j] for i in range(3) for j in range(4)] == \
            [f[i, j] for i in range(3) for j in range(4)]
        clone.p[0] = 42
        assert f.p[0] == 1
    for obj in (K.Vector(1, 2, 3), K.Twist(K.Vector(1, 2, 3), K.Vector(4, 5, 6)),
                K.Wrench(K.Vector(1, 2, 3), K.Vector(4, 5, 6)), K.Rotation.RotX(0.3),
                K.doubleVel(1, 2), K.VectorVel(K.Vector(1, 2, 3), K.Vector(4, 5, 6))):
        assert pickle.loads(pickle.dumps(obj)) == obj
    assert K.Frame().__getstate__()[1] == K.Vector()
    assert K.Rotation.RPY(0.1, 0.2, 0.3).__getstate__() == pytest.approx((0.1, 0.2, 0.3))


def test_repr_is_kdls():
    assert repr(K.Vector(1.23456789, -2e-7, 3e10)) == "[     1.23457,      -2e-07,       3e+10]"
    assert repr(K.Frame()) == ("[[           1,           0,           0;\n"
                               "            0,           1,           0;\n"
                               "            0,           0,           1]\n"
                               "[           0,           0,           0]]")
    assert str(K.Twist()) == "[" + ",".join(["           0"] * 6) + "]"
    assert repr(K.JntArray(2)) == "[           0           0]"
    assert repr(K.doubleVel(1, 2)) == "Rall1d<d, d, d>(1,2)"
    assert repr(K.Joint("j", K.Joint.RotZ)) == (
        "j:[RotZ, axis: [           0,           0,           1], origin[           0,"
        "           0,           0]]")


def test_division_by_zero_gives_ieee_values_as_in_cpp():
    v = K.Vector(1, -2, 0) / 0
    assert v[0] == math.inf and v[1] == -math.inf and math.isnan(v[2])


@pytest.mark.parametrize("call, fragment", [
    (lambda: K.Vector(1, 2), "three numbers"),
    (lambda: K.Vector("a", 2, 3), "three numbers"),
    (lambda: K.Frame(1), "Frame() takes"),
    (lambda: K.Vector()[3], "out of range"),
    (lambda: K.Frame()[3, 3], "out of range"),
    (lambda: K.Rotation()[0], "two integers"),
    (lambda: K.diff(K.Vector(), K.Frame()), "diff() takes one of"),
    (lambda: K.Joint("j", K.Joint.RotAxis), "needs an origin and an axis"),
    (lambda: K.Chain().getSegment(0), "the chain has 0 segments"),
    (lambda: K.Rotation.Identity().Inverse(3), "Rotation.Inverse() takes"),
    (lambda: K.ChainFkSolverPos(), "No constructor defined"),
])
def test_bad_input_is_one_clear_error(call, fragment):
    with pytest.raises((TypeError, IndexError, RuntimeError)) as info:
        call()
    assert fragment in str(info.value)


# ----------------------------------------------------------------- chains and solvers

def arm(seed: int = 0, joints: int = 6) -> K.Chain:
    """A revolute arm with tilted axes and offsets, masses and inertias."""
    rnd = np.random.default_rng(seed)
    chain = K.Chain()
    types = [K.Joint.RotZ, K.Joint.RotY, K.Joint.RotX]
    for i in range(joints):
        if i % 3 == 2:
            axis = K.Vector(*rnd.uniform(-1, 1, 3))
            joint = K.Joint(f"j{i}", K.Vector(*rnd.uniform(-0.1, 0.1, 3)), axis, K.Joint.RotAxis)
        else:
            joint = K.Joint(f"j{i}", types[i % 3])
        tip = K.Frame(K.Rotation.RPY(*rnd.uniform(-1, 1, 3)), K.Vector(*rnd.uniform(-0.4, 0.4, 3)))
        inertia = K.RigidBodyInertia(float(rnd.uniform(0.5, 3)), K.Vector(*rnd.uniform(-0.1, 0.1, 3)),
                                     K.RotationalInertia(*rnd.uniform(0.01, 0.1, 3), 0.001, 0.0, -0.002))
        chain.addSegment(K.Segment(f"s{i}", joint, tip, inertia))
    chain.addSegment(K.Segment("tool", K.Joint(K.Joint.Fixed), K.Frame(K.Vector(0, 0, 0.1))))
    return chain


def jnt(values) -> K.JntArray:
    q = K.JntArray(len(values))
    for i, v in enumerate(values):
        q[i] = float(v)
    return q


def fk(chain: K.Chain, q: K.JntArray) -> K.Frame:
    out = K.Frame()
    assert K.ChainFkSolverPos_recursive(chain).JntToCart(q, out) == 0
    return out


def test_forward_kinematics_is_the_product_of_segment_poses():
    chain = arm(1)
    q = jnt([0.1, -0.4, 0.7, 1.2, -0.3, 0.5])
    expected = K.Frame.Identity()
    j = 0
    for i in range(chain.getNrOfSegments()):
        seg = chain.getSegment(i)
        moving = seg.getJoint().getType() != K.Joint.Fixed
        expected = expected * seg.pose(q[j] if moving else 0.0)
        j += moving
    assert close(fk(chain, q), expected, 1e-12)
    frames = [K.Frame() for _ in range(chain.getNrOfSegments())]
    assert K.ChainFkSolverPos_recursive(chain).JntToCart(q, frames) == 0
    assert close(frames[-1], expected, 1e-12)
    assert K.ChainFkSolverPos_recursive(chain).JntToCart(K.JntArray(2), K.Frame()) == -4


def test_jacobian_matches_finite_differences_of_fk():
    chain = arm(2)
    q = jnt([0.3, 0.2, -0.5, 0.9, 0.1, -1.0])
    jac = K.Jacobian(6)
    assert K.ChainJntToJacSolver(chain).JntToJac(q, jac) == 0
    base = fk(chain, q)
    h = 1e-6
    for j in range(6):
        moved = K.JntArray(q)
        moved[j] += h
        t = K.diff(base, fk(chain, moved), h)
        assert close(jac.getColumn(j), t, 1e-4)


def test_fk_velocity_is_the_jacobian_times_qdot():
    chain = arm(3)
    q, qdot = jnt([0.3, 0.2, -0.5, 0.9, 0.1, -1.0]), jnt([0.5, -0.2, 0.1, 0.3, -0.7, 0.2])
    out = K.FrameVel()
    assert K.ChainFkSolverVel_recursive(chain).JntToCart(K.JntArrayVel(q, qdot), out) == 0
    jac = K.Jacobian(6)
    K.ChainJntToJacSolver(chain).JntToJac(q, jac)
    expected = K.Twist()
    K.MultiplyJacobian(jac, qdot, expected)
    assert close(out.GetTwist(), expected, 1e-12)
    assert close(out.GetFrame(), fk(chain, q), 1e-12)


@pytest.mark.parametrize("make, tol", [
    (lambda c, fks, vik: K.ChainIkSolverPos_NR(c, fks, vik), 1e-6),
    (lambda c, fks, vik: K.ChainIkSolverPos_NR_JL(c, jnt([-3] * 6), jnt([3] * 6), fks, vik), 1e-6),
    # the error LMA stops at is weighted: orientation by 0.01 by default
    (lambda c, fks, vik: K.ChainIkSolverPos_LMA(c), 1e-3),
])
def test_position_ik_reaches_the_target(make, tol):
    chain = arm(4)
    fks, vik = K.ChainFkSolverPos_recursive(chain), K.ChainIkSolverVel_pinv(chain)
    target = fk(chain, jnt([0.4, -0.3, 0.6, 1.0, -0.5, 0.2]))
    solver = make(chain, fks, vik)
    q_out = K.JntArray(6)
    assert solver.CartToJnt(jnt([0.3, -0.2, 0.4, 0.8, -0.3, 0.1]), target, q_out) == 0
    assert close(fk(chain, q_out), target, tol)
    assert solver.strError(0) == "No error"


def test_velocity_ik_inverts_the_jacobian():
    chain = arm(5)
    q = jnt([0.3, 0.2, -0.5, 0.9, 0.1, -1.0])
    twist = K.Twist(K.Vector(0.1, -0.2, 0.3), K.Vector(0.2, 0.1, -0.1))
    jac = K.Jacobian(6)
    K.ChainJntToJacSolver(chain).JntToJac(q, jac)
    for solver in (K.ChainIkSolverVel_pinv(chain), K.ChainIkSolverVel_wdls(chain),
                   K.ChainIkSolverVel_pinv_givens(chain)):
        qdot = K.JntArray(6)
        assert solver.CartToJnt(q, twist, qdot) == 0
        back = K.Twist()
        K.MultiplyJacobian(jac, qdot, back)
        assert close(back, twist, 1e-9), type(solver).__name__
    # a singular arm (two parallel axes through one point) is reported as such
    flat = K.Chain()
    for _ in range(6):
        flat.addSegment(K.Segment(K.Joint(K.Joint.RotZ), K.Frame(K.Vector(0.1, 0, 0))))
    assert K.ChainIkSolverVel_pinv(flat).CartToJnt(K.JntArray(6), twist, K.JntArray(6)) == 100
    assert K.ChainIkSolverVel_pinv(flat).strError(100).startswith("Converged put pseudo inverse")


def test_dynamics_satisfy_the_equation_of_motion():
    chain = arm(6)
    grav = K.Vector(0, 0, -9.81)
    q, qd, qdd = (jnt([0.3, 0.2, -0.5, 0.9, 0.1, -1.0]), jnt([0.5, -0.2, 0.1, 0.3, -0.7, 0.2]),
                  jnt([0.1, 0.4, -0.3, 0.2, 0.5, -0.6]))
    tau = K.JntArray(6)
    rne = K.ChainIdSolver_RNE(chain, grav)
    assert rne.CartToJnt(q, qd, qdd, [K.Wrench()] * chain.getNrOfSegments(), tau) == 0
    dyn = K.ChainDynParam(chain, grav)
    mass, cor, g = K.JntSpaceInertiaMatrix(6), K.JntArray(6), K.JntArray(6)
    assert dyn.JntToMass(q, mass) == 0 and dyn.JntToCoriolis(q, qd, cor) == 0
    assert dyn.JntToGravity(q, g) == 0
    hqdd = K.JntArray(6)
    K.Multiply(mass, qdd, hqdd)
    for i in range(6):
        assert math.isclose(tau[i], hqdd[i] + cor[i] + g[i], rel_tol=1e-9, abs_tol=1e-9)
        assert all(math.isclose(mass[i, j], mass[j, i]) for j in range(6))


def test_jacobian_derivative_matches_finite_differences():
    chain = arm(7)
    q, qd = jnt([0.3, 0.2, -0.5, 0.9, 0.1, -1.0]), jnt([0.5, -0.2, 0.1, 0.3, -0.7, 0.2])
    jdot = K.Jacobian(6)
    assert K.ChainJntToJacDotSolver(chain).JntToJacDot(K.JntArrayVel(q, qd), jdot) == 0
    h = 1e-6
    ahead = K.JntArray(6)
    K.Add(q, jnt([h * qd[i] for i in range(6)]), ahead)
    j0, j1 = K.Jacobian(6), K.Jacobian(6)
    solver = K.ChainJntToJacSolver(chain)
    solver.JntToJac(q, j0)
    solver.JntToJac(ahead, j1)
    for i in range(6):
        for j in range(6):
            assert math.isclose(jdot[i, j], (j1[i, j] - j0[i, j]) / h, abs_tol=1e-4)


def test_solvers_notice_a_chain_that_grew():
    chain = arm(8)
    solver = K.ChainIkSolverVel_pinv(chain)
    chain.addSegment(K.Segment(K.Joint(K.Joint.RotZ)))
    assert solver.CartToJnt(K.JntArray(7), K.Twist(), K.JntArray(7)) == -3
    assert solver.strError(-3) == "Internal data structures not up to date with Chain"
    solver.updateInternalDataStructures()
    assert solver.CartToJnt(K.JntArray(7), K.Twist(), K.JntArray(7)) in (0, 100)


def test_tree_chains_walk_up_and_down():
    tree = K.Tree("base")
    chain = arm(9)
    assert tree.addChain(chain, "base")
    assert not tree.addSegment(K.Segment("s0"), "base")  # the name is taken
    assert not tree.addSegment(K.Segment("x"), "nowhere")
    assert tree.addSegment(K.Segment("side", K.Joint("js", K.Joint.RotY), K.Frame(K.Vector(0, 0.2, 0))), "s2")
    assert (tree.getNrOfJoints(), tree.getNrOfSegments()) == (7, 8)
    down = tree.getChain("base", "tool")
    assert down.getNrOfSegments() == chain.getNrOfSegments()
    q = jnt([0.1, 0.2, 0.3, 0.4, 0.5, 0.6])
    assert close(fk(down, q), fk(chain, q), 1e-12)
    # from the tool back to the base: the inverse pose, joints reversed
    up = tree.getChain("tool", "base")
    back = jnt([0.6, 0.5, 0.4, 0.3, 0.2, 0.1])
    assert close(fk(up, back), fk(chain, q).Inverse(), 1e-9)
    assert tree.getChain("nope", "tool").getNrOfSegments() == 0


def test_segments_are_copied_into_chains():
    seg = K.Segment("s", K.Joint(K.Joint.RotZ))
    chain = K.Chain()
    chain.addSegment(seg)
    seg.setInertia(K.RigidBodyInertia(5.0))
    assert chain.getSegment(0).getInertia().getMass() == 0.0
    chain.getSegment(0).setInertia(K.RigidBodyInertia(3.0))
    assert chain.getSegment(0).getInertia().getMass() == 0.0


def test_inertia_transforms_keep_the_body_the_same():
    body = K.RigidBodyInertia(2.0, K.Vector(0.1, -0.2, 0.3), K.RotationalInertia(0.1, 0.2, 0.3, 0.01, 0.0, 0.02))
    f = K.Frame(K.Rotation.RPY(0.2, 0.3, -0.4), K.Vector(1, 2, 3))
    moved = f * body
    assert math.isclose(moved.getMass(), 2.0)
    assert close(moved.getCOG(), f * body.getCOG(), 1e-12)
    # the momentum of a moving body does not depend on the frame it is written in
    t = K.Twist(K.Vector(0.3, 0.1, -0.2), K.Vector(0.5, -0.4, 0.2))
    assert close(f * (body * t), moved * (f * t), 1e-12)
    assert close(body.RefPoint(K.Vector(1, 0, 0)) * t.RefPoint(K.Vector(1, 0, 0)),
                 (body * t).RefPoint(K.Vector(1, 0, 0)), 1e-12)


def test_joint_types_and_arrays():
    assert K.Joint.RotZ is K.Joint.JointType.RotZ and int(K.Joint.Fixed) == 8
    assert repr(K.Joint.RotZ) == "<JointType.RotZ: 3>"
    j = K.Joint("slide", K.Vector(1, 0, 0), K.Vector(0, 0, 2), K.Joint.TransAxis, 2.0, 0.5)
    assert close(j.pose(1.0).p, K.Vector(1, 0, 2.5)) and close(j.JointAxis(), K.Vector(0, 0, 1))
    assert close(j.twist(1.5).vel, K.Vector(0, 0, 3))
    q = K.JntArray(3)
    q[1] = 2.5
    q.resize(5)
    assert list(q) == [0, 2.5, 0, 0, 0] and q.rows() == 5 and q.columns() == 1
    with pytest.raises(IndexError):
        q[-1]
    a, b = K.JntArray(2), K.JntArray(2)
    b[0] = 1e-8
    assert a == b and not a == K.JntArray(3)
    jac = K.Jacobian(2)
    jac[5, 1] = 2.5
    assert jac.getColumn(1).rot[2] == 2.5 and (jac.rows(), jac.columns()) == (6, 2)
    jac.resize(3)
    assert jac.columns() == 3 and jac[5, 1] == 2.5
