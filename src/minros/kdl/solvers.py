"""PyKDL's chain solvers: forward position and velocity kinematics, Jacobians, inverse velocity
and position kinematics, inverse dynamics and the dynamic parameters.

Each solver keeps a reference to its Chain, as KDL's do; a solver that sizes itself from the
chain answers ``E_NOT_UP_TO_DATE`` (-3) after the chain grows until ``updateInternalDataStructures``
is called. Results are written into the output objects the caller passes (a Frame, JntArray,
Jacobian, ...) and the return value is KDL's error code (0 for success), which ``strError``
describes. The algorithms are KDL's, step for step, so that iterative solvers take the same
path: Newton-Raphson adds the pseudo-inverse step before testing convergence (NR_JL tests
first), Levenberg-Marquardt adapts lambda as KDL does. Singular value decompositions come from
numpy; the pseudo-inverse a truncated SVD gives does not depend on how it was computed.
The forward kinematics compose poses as plain numbers (see kinfam) instead of Frame objects.
"""

from __future__ import annotations

import math
from typing import Any, List, Optional, Sequence

import numpy as np

from .frames import EPSILON, Frame, Twist, Vector, Wrench, _cross, _rot_mul
from .framevel import FrameVel, _fv, _rv, _vv
from .kinfam import (
    _IDENTITY12,
    Chain,
    Jacobian,
    JntArray,
    JntArrayVel,
    JntSpaceInertiaMatrix,
    _mul12,
)

__all__ = ["SolverI", "ChainFkSolverPos", "ChainFkSolverPos_recursive", "ChainFkSolverVel",
           "ChainFkSolverVel_recursive", "ChainJntToJacSolver", "ChainJntToJacDotSolver",
           "ChainIkSolverVel", "ChainIkSolverVel_pinv", "ChainIkSolverVel_pinv_givens",
           "ChainIkSolverVel_pinv_nso", "ChainIkSolverVel_wdls", "ChainIkSolverPos",
           "ChainIkSolverPos_NR", "ChainIkSolverPos_NR_JL", "ChainIkSolverPos_LMA",
           "ChainIdSolver", "ChainIdSolver_RNE", "ChainDynParam"]

# SolverI's error codes
E_DEGRADED = 1
E_NOERROR = 0
E_NO_CONVERGE = -1
E_UNDEFINED = -2
E_NOT_UP_TO_DATE = -3
E_SIZE_MISMATCH = -4
E_MAX_ITERATIONS_EXCEEDED = -5
E_OUT_OF_RANGE = -6
E_NOT_IMPLEMENTED = -7
E_SVD_FAILED = -8

_MESSAGES = {
    E_NOERROR: "No error",
    E_NO_CONVERGE: "Failed to converge",
    E_UNDEFINED: "Undefined value",
    E_DEGRADED: "Converged but degraded solution",
    E_NOT_UP_TO_DATE: "Internal data structures not up to date with Chain",
    E_SIZE_MISMATCH: "The size of the input does not match the internal state",
    E_MAX_ITERATIONS_EXCEEDED: "The maximum number of iterations is exceeded",
    E_OUT_OF_RANGE: "The requested index is out of range",
    E_NOT_IMPLEMENTED: "The requested function is not yet implemented",
    E_SVD_FAILED: "SVD failed",
}
_PINV_SINGULAR = "Converged put pseudo inverse of jacobian is singular."  # KDL's text


def _check(value: Any, cls: type, what: str) -> Any:
    if not isinstance(value, cls):
        raise TypeError(f"{what} must be a {cls.__name__}, got {type(value).__name__}")
    return value


def _abstract(self: Any) -> None:
    raise TypeError(f"PyKDL.{type(self).__name__}: No constructor defined! (use one of its "
                    "subclasses, such as ChainFkSolverPos_recursive)")


class SolverI:
    """What every solver shares: the last error code and its description."""

    _messages: dict = {}
    __init__ = _abstract

    def getError(self) -> int:  # noqa: N802
        """The code the last call returned."""
        return self._error

    def strError(self, error: int) -> str:  # noqa: N802
        """The description of error code ``error``."""
        if error in self._messages:
            return self._messages[error]
        return _MESSAGES.get(error, "UNKNOWN ERROR")

    def updateInternalDataStructures(self) -> None:  # noqa: N802
        """Resize for the chain's current number of joints and segments."""


# ------------------------------------------------------------------------ forward kinematics

def _fk12(chain: Chain, q: Sequence[float], count: int) -> tuple:
    """The pose of segment ``count``'s tip (twelve numbers) at joint positions ``q``: the
    segments' poses multiplied from the base, written out (this loop is the hot path of every
    forward kinematics and IK iteration)."""
    acc = None
    j = 0
    for seg in chain._segments[:count]:
        if seg._joint._type != 8:
            pose = seg._pose12(q[j])
            j += 1
        else:
            pose = seg._tip
        if acc is None:
            acc = pose
            continue
        a0, a1, a2, a3, a4, a5, a6, a7, a8, ax, ay, az = acc
        b0, b1, b2, b3, b4, b5, b6, b7, b8, bx, by, bz = pose
        acc = (a0 * b0 + a1 * b3 + a2 * b6, a0 * b1 + a1 * b4 + a2 * b7,
               a0 * b2 + a1 * b5 + a2 * b8, a3 * b0 + a4 * b3 + a5 * b6,
               a3 * b1 + a4 * b4 + a5 * b7, a3 * b2 + a4 * b5 + a5 * b8,
               a6 * b0 + a7 * b3 + a8 * b6, a6 * b1 + a7 * b4 + a8 * b7,
               a6 * b2 + a7 * b5 + a8 * b8, a0 * bx + a1 * by + a2 * bz + ax,
               a3 * bx + a4 * by + a5 * bz + ay, a6 * bx + a7 * by + a8 * bz + az)
    return _IDENTITY12 if acc is None else acc


def _store(frame: Frame, pose: Sequence[float]) -> None:
    frame._M._d = list(pose[:9])
    frame._p._d = list(pose[9:])


class ChainFkSolverPos(SolverI):
    """Forward position kinematics (abstract; see ChainFkSolverPos_recursive)."""

    def JntToCart(self, q_in: JntArray, p_out: Any, segmentNr: int = -1) -> int:  # noqa: N802, N803
        raise NotImplementedError


class ChainFkSolverPos_recursive(ChainFkSolverPos):  # noqa: N801
    """``JntToCart(q_in, p_out, segmentNr=-1)`` writes into Frame ``p_out`` the pose of the
    tip of segment ``segmentNr`` (all segments by default); given a list of ``segmentNr``
    Frames instead, it writes every segment's pose into it."""

    def __init__(self, chain: Chain) -> None:
        self._chain = _check(chain, Chain, "chain")
        self._error = E_NOERROR

    def JntToCart(self, q_in: JntArray, p_out: Any, segmentNr: int = -1) -> int:  # noqa: N802, N803
        chain = self._chain
        nseg = len(chain._segments)
        count = nseg if segmentNr < 0 else segmentNr
        if isinstance(p_out, list):
            return self._to_list(q_in, p_out, count)
        _check(p_out, Frame, "p_out")
        q = _check(q_in, JntArray, "q_in")._d
        if len(q) != chain._nj:
            _store(p_out, _IDENTITY12)
            self._error = E_SIZE_MISMATCH
        elif count > nseg:
            _store(p_out, _IDENTITY12)
            self._error = E_OUT_OF_RANGE
        else:
            _store(p_out, _fk12(chain, q, count))
            self._error = E_NOERROR
        return self._error

    def _to_list(self, q_in: JntArray, p_out: List[Any], count: int) -> int:
        chain = self._chain
        q = _check(q_in, JntArray, "q_in")._d
        if len(q) != chain._nj or count > len(chain._segments) or len(p_out) != count or count == 0:
            return -1
        acc = None
        j = 0
        for i, seg in enumerate(chain._segments[:count]):
            if seg._joint._type != 8:
                pose = seg._pose12(q[j])
                j += 1
            else:
                pose = seg._tip
            acc = pose if acc is None else _mul12(acc, pose)
            if isinstance(p_out[i], Frame):
                _store(p_out[i], acc)
            else:
                p_out[i] = Frame()
                _store(p_out[i], acc)
        return 0


class ChainFkSolverVel(SolverI):
    """Forward velocity kinematics (abstract; see ChainFkSolverVel_recursive)."""

    def JntToCart(self, q_in: JntArrayVel, out: FrameVel, segmentNr: int = -1) -> int:  # noqa: N802, N803
        raise NotImplementedError


class ChainFkSolverVel_recursive(ChainFkSolverVel):  # noqa: N801
    """``JntToCart(q_in, out, segmentNr=-1)``: the FrameVel (pose and twist in the base frame)
    of a segment's tip for JntArrayVel ``q_in``."""

    def __init__(self, chain: Chain) -> None:
        self._chain = _check(chain, Chain, "chain")
        self._error = E_NOERROR

    def JntToCart(self, q_in: JntArrayVel, out: FrameVel, segmentNr: int = -1) -> int:  # noqa: N802, N803
        _check(q_in, JntArrayVel, "q_in")
        _check(out, FrameVel, "p_out")
        chain = self._chain
        nseg = len(chain._segments)
        count = nseg if segmentNr < 0 else segmentNr
        result = FrameVel.Identity()
        q, qdot = q_in._q._d, q_in._qdot._d
        if not (len(q) == chain._nj and len(qdot) == chain._nj):
            self._error = E_SIZE_MISMATCH
        elif count > nseg:
            self._error = E_OUT_OF_RANGE
        else:
            j = 0
            for seg in chain._segments[:count]:
                if seg._joint._type != 8:
                    qj, qdj = q[j], qdot[j]
                    j += 1
                else:
                    qj = qdj = 0.0
                pose = seg._pose12(qj)
                vel, rot = seg._twist6(qj, qdj)
                result = result * _fv(_rv(list(pose[:9]), rot), _vv(list(pose[9:]), vel))
            self._error = E_NOERROR
        out._M._R._d, out._M._w._d = result._M._R._d, result._M._w._d
        out._p._p._d, out._p._v._d = result._p._p._d, result._p._v._d
        return self._error


# ------------------------------------------------------------------------------- Jacobians

def _jacobian_columns(chain: Chain, q: Sequence[float], count: int, locked: Sequence[bool]
                      ) -> List[tuple]:
    """(column index, column) of every unlocked joint among the first ``count`` segments,
    referred to the tip of segment ``count`` and expressed in the base frame: a revolute
    joint's column is (w x (p_end - o), w) with w its axis and o its origin in the base, a
    prismatic joint's (u, 0) with u its axis (the twist KDL builds segment by segment and
    refers to the end, in closed form)."""
    pending = []
    acc = _IDENTITY12
    j = k = 0
    for seg in chain._segments[:count]:
        joint = seg._joint
        kind = joint._type
        if kind != 8:
            qj = q[j]
            pose = seg._pose12(qj)
            if not locked[j]:
                a0, a1, a2, a3, a4, a5, a6, a7, a8, ax, ay, az = acc
                ux, uy, uz = joint._unit
                s = joint._scale
                u = (s * (a0 * ux + a1 * uy + a2 * uz), s * (a3 * ux + a4 * uy + a5 * uz),
                     s * (a6 * ux + a7 * uy + a8 * uz))
                if kind <= 3:
                    ox, oy, oz = joint._origin
                    origin = (a0 * ox + a1 * oy + a2 * oz + ax, a3 * ox + a4 * oy + a5 * oz + ay,
                              a6 * ox + a7 * oy + a8 * oz + az)
                    pending.append((k, u, origin))
                else:
                    pending.append((k, u, None))
                k += 1
            j += 1
        else:
            pose = seg._tip
        acc = _mul12(acc, pose)
    ex, ey, ez = acc[9], acc[10], acc[11]
    columns = []
    for k, (wx, wy, wz), origin in pending:
        if origin is None:
            columns.append((k, [wx, wy, wz, 0.0, 0.0, 0.0]))
            continue
        rx, ry, rz = ex - origin[0], ey - origin[1], ez - origin[2]
        columns.append((k, [wy * rz - wz * ry, wz * rx - wx * rz, wx * ry - wy * rx, wx, wy, wz]))
    return columns


class ChainJntToJacSolver(SolverI):
    """``JntToJac(q_in, jac, seg_nr=-1)``: the Jacobian of a segment's tip, in the base frame,
    written into ``jac`` (which must have a column per joint); ``setLockedJoints`` leaves
    joints out (their columns are dropped, the later ones move left)."""

    def __init__(self, chain: Chain) -> None:
        self._chain = _check(chain, Chain, "chain")
        self._locked = [False] * chain._nj
        self._error = E_NOERROR

    def updateInternalDataStructures(self) -> None:  # noqa: N802
        n = self._chain._nj
        self._locked = (self._locked + [False] * n)[:n]

    def setLockedJoints(self, locked_joints: Sequence[bool]) -> int:  # noqa: N802
        if len(self._locked) != self._chain._nj:
            self._error = E_NOT_UP_TO_DATE
        elif len(locked_joints) != len(self._locked):
            self._error = E_SIZE_MISMATCH
        else:
            self._locked = [bool(x) for x in locked_joints]
            self._error = E_NOERROR
        return self._error

    def JntToJac(self, q_in: JntArray, jac: Jacobian, seg_nr: int = -1) -> int:  # noqa: N802
        chain = self._chain
        if len(self._locked) != chain._nj:
            self._error = E_NOT_UP_TO_DATE
            return self._error
        q = _check(q_in, JntArray, "q_in")._d
        _check(jac, Jacobian, "jac")
        nseg = len(chain._segments)
        count = nseg if seg_nr < 0 else seg_nr
        jac._c = [[0.0] * 6 for _ in jac._c]
        if len(q) != chain._nj or len(jac._c) != chain._nj:
            self._error = E_SIZE_MISMATCH
        elif count > nseg:
            self._error = E_OUT_OF_RANGE
        else:
            for k, column in _jacobian_columns(chain, q, count, self._locked):
                jac._c[k] = column
            self._error = E_NOERROR
        return self._error

    def _matrix(self, q: Sequence[float]) -> np.ndarray:
        """The 6 x n Jacobian of the whole chain as an array (for the IK solvers)."""
        n = self._chain._nj
        out = np.zeros((n, 6))
        for k, column in _jacobian_columns(self._chain, q, len(self._chain._segments), self._locked):
            out[k] = column
        return out.T


def _twist_cross(a: Twist, b: Twist) -> Twist:
    """KDL's Twist * Twist (the motion cross product)."""
    return Twist(a.rot * b.vel + a.vel * b.rot, a.rot * b.rot)


class ChainJntToJacDotSolver(SolverI):
    """``JntToJacDot(q_in, jdot, seg_nr=-1)``: the time derivative of the Jacobian for
    JntArrayVel ``q_in`` (or, given a Twist, its product with ``q_in.qdot``); in the HYBRID
    representation (base orientation, tip reference point) by default."""

    E_JAC_DOT_FAILED = -100
    E_JACSOLVER_FAILED = -101
    E_FKSOLVERPOS_FAILED = -102
    HYBRID = 0
    BODYFIXED = 1
    INERTIAL = 2
    _messages = {-100: "Jac Dot Failed", -101: "Jac Solver Failed",
                 -102: "FK Position Solver Failed"}

    def __init__(self, chain: Chain) -> None:
        self._chain = _check(chain, Chain, "chain")
        self._locked = [False] * chain._nj
        self._unlocked = chain._nj
        self._representation = self.HYBRID
        self._jac_solver = ChainJntToJacSolver(chain)
        self._fk_solver = ChainFkSolverPos_recursive(chain)
        self._error = E_NOERROR

    def updateInternalDataStructures(self) -> None:  # noqa: N802
        n = self._chain._nj
        self._locked = (self._locked + [False] * n)[:n]
        self.setLockedJoints(self._locked)
        self._jac_solver.updateInternalDataStructures()

    def setLockedJoints(self, locked_joints: Sequence[bool]) -> int:  # noqa: N802
        if len(locked_joints) != len(self._locked):
            return E_SIZE_MISMATCH
        self._locked = [bool(x) for x in locked_joints]
        self._unlocked = self._locked.count(False)
        self._error = E_NOERROR
        return self._error

    def setRepresentation(self, representation: int) -> None:  # noqa: N802
        if representation in (self.HYBRID, self.BODYFIXED, self.INERTIAL):
            self._representation = representation

    def setHybridRepresentation(self) -> None:  # noqa: N802
        self.setRepresentation(self.HYBRID)

    def setBodyFixedRepresentation(self) -> None:  # noqa: N802
        self.setRepresentation(self.BODYFIXED)

    def setInertialRepresentation(self) -> None:  # noqa: N802
        self.setRepresentation(self.INERTIAL)

    def JntToJacDot(self, q_in: JntArrayVel, out: Any, seg_nr: int = -1) -> int:  # noqa: N802
        _check(q_in, JntArrayVel, "q_in")
        if isinstance(out, Twist):
            jdot = Jacobian(self._unlocked)
            self._error = self.JntToJacDot(q_in, jdot, seg_nr)
            if self._error != E_NOERROR:
                return self._error
            qdot = q_in._qdot._d
            vals = [sum(c[i] * qdot[k] for k, c in enumerate(jdot._c)) for i in range(6)]
            out._vel._d, out._rot._d = vals[:3], vals[3:]
            return self._error
        jdot = _check(out, Jacobian, "jdot")
        chain = self._chain
        if len(self._locked) != chain._nj:
            self._error = E_NOT_UP_TO_DATE
            return self._error
        nseg = len(chain._segments)
        count = nseg if seg_nr < 0 else seg_nr
        jdot._c = [[0.0] * 6 for _ in jdot._c]
        if len(q_in._q._d) != chain._nj or self._unlocked != len(jdot._c):
            self._error = E_SIZE_MISMATCH
            return self._error
        if count > nseg:
            self._error = E_OUT_OF_RANGE
            return self._error
        jac = Jacobian(chain._nj)
        if self._jac_solver.JntToJac(q_in._q, jac, count) != E_NOERROR:
            self._error = self.E_JACSOLVER_FAILED
            return self._error
        rep = self._representation
        if rep != self.HYBRID:
            pose = Frame()
            if self._fk_solver.JntToCart(q_in._q, pose, count) != E_NOERROR:
                self._error = self.E_FKSOLVERPOS_FAILED
                return self._error
            if rep == self.BODYFIXED:
                jac.changeBase(pose.M.Inverse())
            else:
                jac.changeRefPoint(-pose.p)
        columns = [jac.getColumn(i) for i in range(chain._nj)]
        qdot = q_in._qdot._d
        k = 0
        for seg in chain._segments[:count]:
            if seg._joint._type == 8:
                continue
            total = Twist()
            for j in range(chain._nj):
                if not self._locked[j]:
                    total += self._partial(columns, j, k, rep) * qdot[j]
            jdot.setColumn(k, total)
            k += 1
        self._error = E_NOERROR
        return self._error

    @staticmethod
    def _partial(columns: List[Twist], j: int, i: int, rep: int) -> Twist:
        """d(column i)/d(q_j) in the chosen representation."""
        cj, ci = columns[j], columns[i]
        if rep == ChainJntToJacDotSolver.HYBRID:
            if j < i:
                return Twist(cj.rot * ci.vel, cj.rot * ci.rot)
            if j > i:
                return Twist(-cj.vel * ci.rot, Vector())
            return Twist(ci.rot * ci.vel, Vector())
        if rep == ChainJntToJacDotSolver.BODYFIXED:
            return -_twist_cross(cj, ci) if j > i else Twist()
        return _twist_cross(cj, ci) if j < i else Twist()


# --------------------------------------------------------------- inverse velocity kinematics

class ChainIkSolverVel(SolverI):
    """Inverse velocity kinematics (abstract; see ChainIkSolverVel_pinv)."""

    def CartToJnt(self, q_in: JntArray, v_in: Twist, qdot_out: JntArray) -> int:  # noqa: N802
        raise NotImplementedError


def _twist_array(v: Twist) -> np.ndarray:
    return np.array(v._vel._d + v._rot._d)


class _VelocitySolver(ChainIkSolverVel):
    """What the SVD-based velocity solvers share: the chain, its Jacobian solver, the checks."""

    _messages = {100: _PINV_SINGULAR}

    def __init__(self, chain: Chain, eps: float = 0.00001, maxiter: int = 150) -> None:
        self._chain = _check(chain, Chain, "chain")
        self._jac = ChainJntToJacSolver(chain)
        self._nj = chain._nj
        self._eps = float(eps)
        self._maxiter = int(maxiter)
        self._error = E_NOERROR

    def updateInternalDataStructures(self) -> None:  # noqa: N802
        self._jac.updateInternalDataStructures()
        self._nj = self._chain._nj

    def _prepare(self, q_in: JntArray, v_in: Twist, qdot_out: JntArray, *sized: JntArray) -> Any:
        """The Jacobian array, or an error code."""
        _check(q_in, JntArray, "q_in")
        _check(v_in, Twist, "v_in")
        _check(qdot_out, JntArray, "qdot_out")
        nj = self._nj
        if nj != self._chain._nj:
            return E_NOT_UP_TO_DATE
        if nj != len(q_in._d) or nj != len(qdot_out._d) or any(nj != len(s._d) for s in sized):
            return E_SIZE_MISMATCH
        if len(self._jac._locked) != self._chain._nj:
            return E_NOT_UP_TO_DATE
        return self._jac._matrix(q_in._d)


def _svd(jac: np.ndarray) -> Any:
    try:
        return np.linalg.svd(jac, full_matrices=False)
    except np.linalg.LinAlgError:
        return None


class ChainIkSolverVel_pinv(_VelocitySolver):  # noqa: N801
    """``CartToJnt(q_in, v_in, qdot_out)``: joint velocities for twist ``v_in`` through the
    Jacobian's pseudo-inverse, singular values below ``eps`` left out (truncated SVD); returns
    100 (E_CONVERGE_PINV_SINGULAR) when the Jacobian is singular."""

    def CartToJnt(self, q_in: JntArray, v_in: Twist, qdot_out: JntArray) -> int:  # noqa: N802
        jac = self._prepare(q_in, v_in, qdot_out)
        if isinstance(jac, int):
            self._error = jac
            return jac
        nj = self._nj
        if nj == 0:
            self._error = E_NOERROR
            return self._error
        parts = _svd(jac)
        if parts is None:
            qdot_out._d = [0.0] * nj
            self._error = E_SVD_FAILED
            return self._error
        u, s, vt = parts
        small = np.abs(s) < self._eps
        tmp = np.where(small, 0.0, (u.T @ _twist_array(v_in)) / np.where(small, 1.0, s))
        qdot_out._d = (vt.T @ tmp).tolist()
        zero_sigmas = int(small.sum()) + max(0, nj - 6)
        # KDL compares with columns() - rows() in unsigned arithmetic: below six joints the
        # difference wraps around and the solution is never reported singular.
        self._error = 100 if nj >= 6 and zero_sigmas > nj - 6 else E_NOERROR
        return self._error


class ChainIkSolverVel_pinv_givens(_VelocitySolver):  # noqa: N801
    """``CartToJnt``: the pseudo-inverse solution with only exactly-zero singular values left
    out (KDL computes the SVD with Givens rotations; numpy's tiny round-off values are taken
    as those zeros)."""

    def __init__(self, chain: Chain) -> None:
        super().__init__(chain)

    def CartToJnt(self, q_in: JntArray, v_in: Twist, qdot_out: JntArray) -> int:  # noqa: N802
        jac = self._prepare(q_in, v_in, qdot_out)
        if isinstance(jac, int):
            self._error = jac
            return jac
        if self._nj == 0:
            self._error = E_NOERROR
            return self._error
        parts = _svd(jac)
        if parts is None:
            qdot_out._d = [0.0] * self._nj
            self._error = E_SVD_FAILED
            return self._error
        u, s, vt = parts
        zero = s <= (s[0] if len(s) else 0.0) * max(jac.shape) * np.finfo(float).eps
        tmp = np.where(zero, 0.0, (u.T @ _twist_array(v_in)) / np.where(zero, 1.0, s))
        qdot_out._d = (vt.T @ tmp).tolist()
        self._error = E_NOERROR
        return self._error


class ChainIkSolverVel_pinv_nso(_VelocitySolver):  # noqa: N801
    """The pseudo-inverse solution plus a null-space motion towards ``setOptPos`` positions,
    weighted by ``setWeights`` and scaled by ``alpha`` (both must be set before solving)."""

    def __init__(self, chain: Chain, eps: float = 0.00001, maxiter: int = 150,
                 alpha: float = 0.25) -> None:
        super().__init__(chain, eps, maxiter)
        self._alpha = float(alpha)
        self._weights = JntArray()
        self._opt_pos = JntArray()

    def setWeights(self, weights: JntArray) -> int:  # noqa: N802
        if self._nj != len(_check(weights, JntArray, "weights")._d):
            self._error = E_SIZE_MISMATCH
        else:
            self._weights = JntArray(weights)
            self._error = E_NOERROR
        return self._error

    def setOptPos(self, opt_pos: JntArray) -> int:  # noqa: N802
        if self._nj != len(_check(opt_pos, JntArray, "opt_pos")._d):
            self._error = E_SIZE_MISMATCH
        else:
            self._opt_pos = JntArray(opt_pos)
            self._error = E_NOERROR
        return self._error

    def setAlpha(self, alpha: float) -> int:  # noqa: N802
        self._alpha = float(alpha)
        return 0

    def getWeights(self) -> JntArray:  # noqa: N802
        return JntArray(self._weights)

    def getOptPos(self) -> JntArray:  # noqa: N802
        return JntArray(self._opt_pos)

    def getAlpha(self) -> float:  # noqa: N802
        return self._alpha

    def CartToJnt(self, q_in: JntArray, v_in: Twist, qdot_out: JntArray) -> int:  # noqa: N802
        jac = self._prepare(q_in, v_in, qdot_out, self._opt_pos, self._weights)
        if isinstance(jac, int):
            self._error = jac
            return jac
        nj = self._nj
        if nj == 0:
            self._error = E_NOERROR
            return self._error
        parts = _svd(jac)
        if parts is None:
            qdot_out._d = [0.0] * nj
            self._error = E_SVD_FAILED
            return self._error
        u, s, vt = parts
        small = np.abs(s) < self._eps
        sinv = np.where(small, 0.0, 1.0 / np.where(small, 1.0, s))
        qdot = vt.T @ (sinv * (u.T @ _twist_array(v_in)))
        q = np.array(q_in._d)
        qd = q - np.array(self._opt_pos._d)
        w = np.array(self._weights._d)
        g = float(np.sum(0.5 * qd * qd * w))
        a = float(np.sum(qd * qd * w * w))
        if a > 1e-9:
            tmp = w * qd / a
            tmp2 = vt.T @ (sinv * (u.T @ (u @ (s * (vt @ tmp)))))
            qdot = qdot - 2 * self._alpha * g * (tmp - tmp2)
        qdot_out._d = qdot.tolist()
        self._error = E_NOERROR
        return self._error


class ChainIkSolverVel_wdls(_VelocitySolver):  # noqa: N801
    """Weighted damped least squares: the pseudo-inverse of ``Wts J Wjs`` with singular values
    below ``eps`` damped by ``lambda`` (``setLambda``; 0 by default, which truncates them)."""

    def __init__(self, chain: Chain, eps: float = 0.00001, maxiter: int = 150) -> None:
        super().__init__(chain, eps, maxiter)
        self._weight_ts = np.eye(6)
        self._weight_js = np.eye(chain._nj)
        self._lambda = 0.0
        self._lambda_scaled = 0.0
        self._zero_sigmas = 0
        self._sigma_min = 0.0
        self._sigma = np.zeros(chain._nj)
        self._svd_result = 0

    def updateInternalDataStructures(self) -> None:  # noqa: N802
        super().updateInternalDataStructures()
        nj = self._nj
        old = self._weight_js
        self._weight_js = np.eye(nj)
        k = min(nj, old.shape[0])
        self._weight_js[:k, :k] = old[:k, :k]
        self._sigma = np.resize(self._sigma, nj)

    def setWeightJS(self, Mq: Any) -> int:  # noqa: N802, N803
        if self._nj != self._chain._nj:
            self._error = E_NOT_UP_TO_DATE
            return self._error
        m = np.asarray(Mq, dtype=float)
        if m.size != self._weight_js.size:
            self._error = E_SIZE_MISMATCH
        else:
            self._weight_js = m.reshape(self._weight_js.shape).copy()
            self._error = E_NOERROR
        return self._error

    def setWeightTS(self, Mx: Any) -> int:  # noqa: N802, N803
        m = np.asarray(Mx, dtype=float)
        if m.size != 36:
            self._error = E_SIZE_MISMATCH
        else:
            self._weight_ts = m.reshape(6, 6).copy()
            self._error = E_NOERROR
        return self._error

    def setLambda(self, lambda_in: float) -> None:  # noqa: N802
        self._lambda = float(lambda_in)

    def setEps(self, eps_in: float) -> None:  # noqa: N802
        self._eps = float(eps_in)

    def setMaxIter(self, maxiter_in: int) -> None:  # noqa: N802
        self._maxiter = int(maxiter_in)

    def getNrZeroSigmas(self) -> int:  # noqa: N802
        return self._zero_sigmas

    def getSigmaMin(self) -> float:  # noqa: N802
        return self._sigma_min

    def getSigma(self, Sout: Any) -> int:  # noqa: N802, N803
        """Copy the singular values into numpy array ``Sout`` (of one per joint)."""
        if np.size(Sout) != self._sigma.size:
            self._error = E_SIZE_MISMATCH
            return self._error
        np.copyto(np.asarray(Sout).reshape(-1), self._sigma)
        self._error = E_NOERROR
        return self._error

    def getEps(self) -> float:  # noqa: N802
        return self._eps

    def getLambda(self) -> float:  # noqa: N802
        return self._lambda

    def getLambdaScaled(self) -> float:  # noqa: N802
        return self._lambda_scaled

    def getSVDResult(self) -> int:  # noqa: N802
        return self._svd_result

    def CartToJnt(self, q_in: JntArray, v_in: Twist, qdot_out: JntArray) -> int:  # noqa: N802
        jac = self._prepare(q_in, v_in, qdot_out)
        if isinstance(jac, int):
            self._error = jac
            return jac
        nj = self._nj
        self._zero_sigmas = 0
        self._sigma_min = 0.0
        self._lambda_scaled = 0.0
        if nj == 0:
            self._error = E_NOERROR
            return self._error
        parts = _svd(self._weight_ts @ jac @ self._weight_js)
        if parts is None:
            qdot_out._d = [0.0] * nj
            self._svd_result = -1
            self._error = E_SVD_FAILED
            return self._error
        self._svd_result = 0
        u, s_thin, vt = parts
        s = np.zeros(nj)
        s[:len(s_thin)] = s_thin
        self._sigma = s
        sums = (self._weight_ts @ u).T @ _twist_array(v_in)
        self._sigma_min = float(s[5]) if nj >= 6 else 0.0
        eps, lam = self._eps, self._lambda
        tmp = np.zeros(len(s_thin))
        for i in range(nj):
            if self._sigma_min < eps:
                self._lambda_scaled = math.sqrt(1.0 - (self._sigma_min / eps) ** 2) * lam
            si = s[i]
            if abs(si) < eps:
                if i < len(s_thin):
                    denominator = si * si + self._lambda_scaled * self._lambda_scaled
                    tmp[i] = sums[i] * (si / denominator) if denominator != 0 else 0.0
                self._zero_sigmas += 1
            elif i < len(s_thin):
                tmp[i] = sums[i] / si
        qdot_out._d = (self._weight_js @ (vt.T @ tmp)).tolist()
        self._error = 100 if nj >= 6 and self._zero_sigmas > nj - 6 else E_NOERROR
        return self._error


# --------------------------------------------------------------- inverse position kinematics

class ChainIkSolverPos(SolverI):
    """Inverse position kinematics (abstract; see ChainIkSolverPos_NR)."""

    def CartToJnt(self, q_init: JntArray, p_in: Frame, q_out: JntArray) -> int:  # noqa: N802
        raise NotImplementedError


def _frame_diff(a: Sequence[float], b: Frame) -> List[float]:
    """KDL's diff(Frame a, Frame b) as six numbers, ``a`` given as twelve."""
    from .frames import _rot_angle, _rot_rot, _transpose

    bp = b._p._d
    vel = [bp[0] - a[9], bp[1] - a[10], bp[2] - a[11]]
    ma = list(a[:9])
    angle, axis = _rot_angle(_rot_rot(_transpose(ma), b._M._d))
    rot = _rot_mul(ma, [axis[0] * angle, axis[1] * angle, axis[2] * angle])
    return vel + rot


def _twist_is_zero(d: Sequence[float], eps: float) -> bool:
    return all(-eps < x < eps for x in d)


class ChainIkSolverPos_NR(ChainIkSolverPos):  # noqa: N801
    """Newton-Raphson: ``CartToJnt(q_init, p_in, q_out)`` iterates FK and the velocity solver
    from ``q_init`` until the pose error is below ``eps`` (at most ``maxiter`` steps)."""

    _E_IKSOLVER_FAILED = -100
    _E_FKSOLVERPOS_FAILED = -101
    _messages = {-100: "Child IK solver failed", -101: "Child FK solver failed"}

    def __init__(self, chain: Chain, fksolver: ChainFkSolverPos, iksolver: ChainIkSolverVel,
                 maxiter: int = 100, eps: float = EPSILON) -> None:
        self._chain = _check(chain, Chain, "chain")
        self._fk = _check(fksolver, ChainFkSolverPos, "fksolver")
        self._ik = _check(iksolver, ChainIkSolverVel, "iksolver")
        self._nj = chain._nj
        self._maxiter = int(maxiter)
        self._eps = float(eps)
        self._error = E_NOERROR

    def updateInternalDataStructures(self) -> None:  # noqa: N802
        self._nj = self._chain._nj
        self._ik.updateInternalDataStructures()
        self._fk.updateInternalDataStructures()

    def CartToJnt(self, q_init: JntArray, p_in: Frame, q_out: JntArray) -> int:  # noqa: N802
        _check(q_init, JntArray, "q_init")
        _check(p_in, Frame, "p_in")
        _check(q_out, JntArray, "q_out")
        nj = self._nj
        if nj != self._chain._nj:
            self._error = E_NOT_UP_TO_DATE
            return self._error
        if len(q_init._d) != nj or len(q_out._d) != nj:
            self._error = E_SIZE_MISMATCH
            return self._error
        q_out._d = q_init._d[:]
        f = Frame()
        delta_q = JntArray(nj)
        delta = Twist()
        for _ in range(self._maxiter):
            if self._fk.JntToCart(q_out, f) < E_NOERROR:
                self._error = self._E_FKSOLVERPOS_FAILED
                return self._error
            d = _frame_diff(_frame12_of(f), p_in)
            delta._vel._d, delta._rot._d = d[:3], d[3:]
            rc = self._ik.CartToJnt(q_out, delta, delta_q)
            if rc < E_NOERROR:
                self._error = self._E_IKSOLVER_FAILED
                return self._error
            q_out._d = [a + b for a, b in zip(q_out._d, delta_q._d)]
            if _twist_is_zero(d, self._eps):
                # converged, perhaps with a degraded solution (KDL leaves getError alone here)
                return E_DEGRADED if rc > E_NOERROR else E_NOERROR
        self._error = E_MAX_ITERATIONS_EXCEEDED
        return self._error


def _frame12_of(f: Frame) -> tuple:
    return (*f._M._d, *f._p._d)


class ChainIkSolverPos_NR_JL(ChainIkSolverPos):  # noqa: N801
    """Newton-Raphson within joint limits: after each step a joint past ``q_min``/``q_max`` is
    clamped to the limit."""

    _E_IKSOLVERVEL_FAILED = -100
    _E_FKSOLVERPOS_FAILED = -101
    _messages = {-100: "Internal inverse velocity solver failed.",
                 -101: "Internal forward position solver failed."}

    def __init__(self, chain: Chain, q_min: JntArray, q_max: JntArray,
                 fksolver: ChainFkSolverPos, iksolver: ChainIkSolverVel, maxiter: int = 100,
                 eps: float = EPSILON) -> None:
        self._chain = _check(chain, Chain, "chain")
        self._q_min = JntArray(_check(q_min, JntArray, "q_min"))
        self._q_max = JntArray(_check(q_max, JntArray, "q_max"))
        self._fk = _check(fksolver, ChainFkSolverPos, "fksolver")
        self._ik = _check(iksolver, ChainIkSolverVel, "iksolver")
        self._nj = chain._nj
        self._maxiter = int(maxiter)
        self._eps = float(eps)
        self._error = E_NOERROR

    def updateInternalDataStructures(self) -> None:  # noqa: N802
        nj = self._nj = self._chain._nj
        lo, hi = self._q_min._d, self._q_max._d
        self._q_min._d = (lo + [2.2250738585072014e-308] * nj)[:nj]
        self._q_max._d = (hi + [1.7976931348623157e308] * nj)[:nj]
        self._ik.updateInternalDataStructures()
        self._fk.updateInternalDataStructures()

    def CartToJnt(self, q_init: JntArray, p_in: Frame, q_out: JntArray) -> int:  # noqa: N802
        _check(q_init, JntArray, "q_init")
        _check(p_in, Frame, "p_in")
        _check(q_out, JntArray, "q_out")
        nj = self._nj
        if nj != self._chain._nj:
            self._error = E_NOT_UP_TO_DATE
            return self._error
        lo, hi = self._q_min._d, self._q_max._d
        if len(q_init._d) != nj or len(q_out._d) != nj or len(lo) != nj or len(hi) != nj:
            self._error = E_SIZE_MISMATCH
            return self._error
        q_out._d = q_init._d[:]
        f = Frame()
        delta_q = JntArray(nj)
        delta = Twist()
        for _ in range(self._maxiter):
            if self._fk.JntToCart(q_out, f) < 0:
                self._error = self._E_FKSOLVERPOS_FAILED
                return self._error
            d = _frame_diff(_frame12_of(f), p_in)
            if _twist_is_zero(d, self._eps):
                self._error = E_NOERROR
                return self._error
            delta._vel._d, delta._rot._d = d[:3], d[3:]
            if self._ik.CartToJnt(q_out, delta, delta_q) < 0:
                self._error = self._E_IKSOLVERVEL_FAILED
                return self._error
            q = [a + b for a, b in zip(q_out._d, delta_q._d)]
            q_out._d = [min(max(v, lo[k]), hi[k]) if (v < lo[k] or v > hi[k]) else v
                        for k, v in enumerate(q)]
        self._error = E_MAX_ITERATIONS_EXCEEDED
        return self._error


class ChainIkSolverPos_LMA(ChainIkSolverPos):  # noqa: N801
    """Levenberg-Marquardt: ``ChainIkSolverPos_LMA(chain, L, eps=1e-5, maxiter=500,
    eps_joints=1e-15)`` with weights ``L`` for the six pose errors (by default 1, 1, 1 for
    position and 0.01, 0.01, 0.01 for orientation); ``L`` may be left out."""

    _E_GRADIENT_JOINTS_TOO_SMALL = -100
    _E_INCREMENT_JOINTS_TOO_SMALL = -101
    _messages = {-100: "The gradient of E towards the joints is to small",
                 -101: "The joint position increments are to small"}

    def __init__(self, chain: Chain, *args: Any, **kwargs: Any) -> None:
        self._chain = _check(chain, Chain, "chain")
        rest = list(args)
        weights: Any = kwargs.pop("L", None)
        if weights is None and rest and np.ndim(rest[0]) > 0:
            weights = rest.pop(0)
        names = ("eps", "maxiter", "eps_joints")
        values = dict(zip(names, rest))
        for key, value in kwargs.items():
            if key not in names or key in values:
                raise TypeError(f"ChainIkSolverPos_LMA() got an unexpected argument {key!r}")
            values[key] = value
        if weights is None:
            self._L = np.array([1.0, 1.0, 1.0, 0.01, 0.01, 0.01])
        else:
            self._L = np.asarray(weights, dtype=float).reshape(-1)
            if self._L.size != 6:
                raise TypeError(f"ChainIkSolverPos_LMA's L has six weights, got {self._L.size}")
        self._eps = float(values.get("eps", 1e-5))
        self._maxiter = int(values.get("maxiter", 500))
        self._eps_joints = float(values.get("eps_joints", 1e-15))
        self._nj = chain._nj
        self._error = E_NOERROR

    def updateInternalDataStructures(self) -> None:  # noqa: N802
        self._nj = self._chain._nj

    def _forward(self, q: Sequence[float]) -> Any:
        """(tip pose, per joint: pose before it and after it), each as twelve numbers."""
        head = _IDENTITY12
        roots, tips = [], []
        j = 0
        for seg in self._chain._segments:
            if seg._joint._type != 8:
                roots.append(head)
                head = _mul12(head, seg._pose12(q[j]))
                tips.append(head)
                j += 1
            else:
                head = _mul12(head, seg._tip)
        return head, roots, tips

    def _jacobian(self, q: Sequence[float], head: Any, roots: Any, tips: Any) -> np.ndarray:
        jac = np.zeros((6, self._nj))
        j = 0
        for seg in self._chain._segments:
            if seg._joint._type == 8:
                continue
            vel, rot = seg._twist6(q[j], 1.0)
            m = roots[j][:9]
            vel, rot = _rot_mul(m, vel), _rot_mul(m, rot)
            tip = tips[j]
            cx, cy, cz = _cross(rot, (head[9] - tip[9], head[10] - tip[10], head[11] - tip[11]))
            jac[:, j] = (vel[0] + cx, vel[1] + cy, vel[2] + cz, *rot)
            j += 1
        return jac

    def CartToJnt(self, q_init: JntArray, p_in: Frame, q_out: JntArray) -> int:  # noqa: N802
        _check(q_init, JntArray, "q_init")
        _check(p_in, Frame, "T_base_goal")
        _check(q_out, JntArray, "q_out")
        nj = self._nj
        if nj != self._chain._nj:
            self._error = E_NOT_UP_TO_DATE
            return self._error
        if nj != len(q_init._d) or nj != len(q_out._d):
            self._error = E_SIZE_MISMATCH
            return self._error
        weights = self._L
        q = np.array(q_init._d, dtype=float)
        head, roots, tips = self._forward(q)
        delta = weights * np.array(_frame_diff(head, p_in))
        delta_norm = float(np.linalg.norm(delta))
        if delta_norm < self._eps:
            q_out._d = q.tolist()
            self._error = E_NOERROR
            return self._error
        jac = weights[:, None] * self._jacobian(q, head, roots, tips)
        lam, v = 10.0, 2.0
        for _ in range(self._maxiter):
            parts = _svd(jac)
            if parts is None:
                q_out._d = q.tolist()
                self._error = E_SVD_FAILED
                return self._error
            u, s, vt = parts
            diffq = vt.T @ ((s / (s * s + lam)) * (u.T @ delta))
            grad = jac.T @ delta
            if (float(np.max(np.abs(diffq))) if diffq.size else 0.0) < self._eps_joints:
                q_out._d = q.tolist()
                self._error = self._E_INCREMENT_JOINTS_TOO_SMALL
                return self._error
            if float(grad @ grad) < self._eps_joints * self._eps_joints:
                q_out._d = q.tolist()
                self._error = self._E_GRADIENT_JOINTS_TOO_SMALL
                return self._error
            q_new = q + diffq
            head, roots, tips = self._forward(q_new)
            delta_new = weights * np.array(_frame_diff(head, p_in))
            new_norm = float(np.linalg.norm(delta_new))
            rho = (delta_norm * delta_norm - new_norm * new_norm) / float(diffq @ (lam * diffq + grad))
            if rho > 0:
                q, delta, delta_norm = q_new, delta_new, new_norm
                if delta_norm < self._eps:
                    q_out._d = q.tolist()
                    self._error = E_NOERROR
                    return self._error
                jac = weights[:, None] * self._jacobian(q, head, roots, tips)
                t = 2 * rho - 1
                lam = lam * max(1 / 3.0, 1 - t * t * t)
                v = 2.0
            else:
                lam = lam * v
                v = 2 * v
        q_out._d = q.tolist()
        self._error = E_MAX_ITERATIONS_EXCEEDED
        return self._error


# ------------------------------------------------------------------------------- dynamics

def _wrench_of(rbi: Any, t: Twist) -> Wrench:
    return rbi * t


def _twist_wrench(t: Twist, w: Wrench) -> Wrench:
    """KDL's Twist * Wrench (the force cross product)."""
    return Wrench(t.rot * w.force, t.rot * w.torque + t.vel * w.force)


class ChainIdSolver(SolverI):
    """Inverse dynamics (abstract; see ChainIdSolver_RNE)."""

    def CartToJnt(self, q: JntArray, q_dot: JntArray, q_dotdot: JntArray,  # noqa: N802
                  f_ext: Sequence[Wrench], torques: JntArray) -> int:
        raise NotImplementedError


class ChainIdSolver_RNE(ChainIdSolver):  # noqa: N801
    """Recursive Newton-Euler: ``CartToJnt(q, q_dot, q_dotdot, f_ext, torques)`` writes the
    joint torques for the motion, under gravity ``grav`` and external wrenches ``f_ext``
    (one per segment, in the segment's tip frame)."""

    def __init__(self, chain: Chain, grav: Vector) -> None:
        self._chain = _check(chain, Chain, "chain")
        self._grav = Vector(_check(grav, Vector, "grav"))
        self._nj = chain._nj
        self._ns = len(chain._segments)
        self._error = E_NOERROR

    def updateInternalDataStructures(self) -> None:  # noqa: N802
        self._nj = self._chain._nj
        self._ns = len(self._chain._segments)

    def CartToJnt(self, q: JntArray, q_dot: JntArray, q_dotdot: JntArray,  # noqa: N802
                  f_ext: Sequence[Wrench], torques: JntArray) -> int:
        chain, nj, ns = self._chain, self._nj, self._ns
        if nj != chain._nj or ns != len(chain._segments):
            self._error = E_NOT_UP_TO_DATE
            return self._error
        if (len(q._d) != nj or len(q_dot._d) != nj or len(q_dotdot._d) != nj
                or len(torques._d) != nj or len(f_ext) != ns):
            self._error = E_SIZE_MISMATCH
            return self._error
        ag = -Twist(self._grav, Vector())
        frames: List[Frame] = []
        axes: List[Twist] = []
        forces: List[Wrench] = []
        v: Optional[Twist] = None
        a: Optional[Twist] = None
        j = 0
        for i, seg in enumerate(chain._segments):
            if seg._joint._type != 8:
                qi, qdi, qddi = q._d[j], q_dot._d[j], q_dotdot._d[j]
                j += 1
            else:
                qi = qdi = qddi = 0.0
            x = seg.pose(qi)
            vj = x.M.Inverse(seg.twist(qi, qdi))
            s = x.M.Inverse(seg.twist(qi, 1.0))
            if i == 0:
                v = vj
                a = x.Inverse(ag) + s * qddi + _twist_cross(v, vj)
            else:
                v = x.Inverse(v) + vj
                a = x.Inverse(a) + s * qddi + _twist_cross(v, vj)
            inertia = seg._I
            forces.append(inertia * a + _twist_wrench(v, inertia * v) - f_ext[i])
            frames.append(x)
            axes.append(s)
        out = torques._d
        j = nj - 1
        for i in range(ns - 1, -1, -1):
            seg = chain._segments[i]
            if seg._joint._type != 8:
                s, f = axes[i], forces[i]
                value = (s._vel._d[0] * f._force._d[0] + s._vel._d[1] * f._force._d[1]
                         + s._vel._d[2] * f._force._d[2] + s._rot._d[0] * f._torque._d[0]
                         + s._rot._d[1] * f._torque._d[1] + s._rot._d[2] * f._torque._d[2])
                out[j] = value + seg._joint._inertia * q_dotdot._d[j]
                j -= 1
            if i != 0:
                forces[i - 1] = forces[i - 1] + frames[i] * forces[i]
        self._error = E_NOERROR
        return self._error


def _dot_tw(t: Twist, w: Wrench) -> float:
    return sum(a * b for a, b in zip(t._vel._d + t._rot._d, w._force._d + w._torque._d))


class ChainDynParam:
    """The terms of a chain's equation of motion: ``JntToMass(q, H)`` (joint-space mass matrix),
    ``JntToCoriolis(q, q_dot, coriolis)`` and ``JntToGravity(q, gravity)``."""

    def __init__(self, chain: Chain, grav: Vector) -> None:
        self._chain = _check(chain, Chain, "chain")
        self._grav = Vector(_check(grav, Vector, "grav"))
        self._nj = chain._nj
        self._ns = len(chain._segments)
        self._coriolis = ChainIdSolver_RNE(chain, Vector())
        self._gravity = ChainIdSolver_RNE(chain, self._grav)
        self._error = E_NOERROR

    def JntToMass(self, q: JntArray, H: JntSpaceInertiaMatrix) -> int:  # noqa: N802, N803
        chain, nj, ns = self._chain, self._nj, self._ns
        if nj != chain._nj or ns != len(chain._segments):
            self._error = E_NOT_UP_TO_DATE
            return self._error
        if len(q._d) != nj or H.rows() != nj:
            self._error = E_SIZE_MISMATCH
            return self._error
        segs = chain._segments
        inertias, frames, axes = [], [], []
        k = 0
        for seg in segs:
            inertias.append(seg._I)
            if seg._joint._type != 8:
                qk = q._d[k]
                k += 1
            else:
                qk = 0.0
            x = seg.pose(qk)
            frames.append(x)
            axes.append(x.M.Inverse(seg.twist(qk, 1.0)))
        rows = H._r
        k = nj - 1
        for i in range(ns - 1, -1, -1):
            if i != 0:
                inertias[i - 1] = inertias[i - 1] + frames[i] * inertias[i]
            force = inertias[i] * axes[i]
            if segs[i]._joint._type != 8:
                rows[k][k] = _dot_tw(axes[i], force) + segs[i]._joint._inertia
                j, seg_index = k, i
                while seg_index != 0:
                    force = frames[seg_index] * force
                    seg_index -= 1
                    if segs[seg_index]._joint._type != 8:
                        j -= 1
                        rows[k][j] = _dot_tw(axes[seg_index], force)
                        rows[j][k] = rows[k][j]
                k -= 1
        self._error = E_NOERROR
        return self._error

    def JntToCoriolis(self, q: JntArray, q_dot: JntArray, coriolis: JntArray) -> int:  # noqa: N802
        zero = JntArray(self._nj)
        return self._coriolis.CartToJnt(q, q_dot, zero, [Wrench()] * self._ns, coriolis)

    def JntToGravity(self, q: JntArray, gravity: JntArray) -> int:  # noqa: N802
        zero = JntArray(self._nj)
        return self._gravity.CartToJnt(q, zero, zero, [Wrench()] * self._ns, gravity)
