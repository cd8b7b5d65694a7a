"""PyKDL in pure Python: Orocos KDL's frames, kinematic chains and solvers, with the Python
names and numbers of Debian's python3-pykdl (KDL 1.5.1, a C++ extension there).

* ``frames``: Vector, Rotation, Frame, Twist, Wrench;
* ``framevel``: doubleVel, VectorVel, RotationVel, FrameVel, TwistVel (values with their
  derivatives);
* ``kinfam``: Joint, Segment, Chain, Tree, RotationalInertia, RigidBodyInertia, JntArray,
  JntArrayVel, Jacobian, JntSpaceInertiaMatrix;
* ``solvers``: forward kinematics (position, velocity), Jacobians (and their derivative),
  inverse velocity kinematics (pseudo-inverse, Givens, null-space, weighted damped least
  squares), inverse position kinematics (Newton-Raphson, with joint limits,
  Levenberg-Marquardt), recursive Newton-Euler and ChainDynParam;
* ``functions``: diff, addDelta, dot, Equal, SetToZero and the joint-space arithmetic.

The ``PyKDL`` package in ``stubs/`` re-exports this one. Only numpy is needed (for the SVDs).
"""

from .frames import Frame, Rotation, Twist, Vector, Wrench
from .framevel import FrameVel, RotationVel, TwistVel, VectorVel, doubleVel
from .functions import (
    Add,
    Divide,
    Equal,
    Multiply,
    MultiplyJacobian,
    SetToZero,
    Subtract,
    addDelta,
    changeBase,
    changeRefPoint,
    diff,
    dot,
)
from .kinfam import (
    Chain,
    Jacobian,
    JntArray,
    JntArrayVel,
    JntSpaceInertiaMatrix,
    Joint,
    RigidBodyInertia,
    RotationalInertia,
    Segment,
    Tree,
)
from .solvers import (
    ChainDynParam,
    ChainFkSolverPos,
    ChainFkSolverPos_recursive,
    ChainFkSolverVel,
    ChainFkSolverVel_recursive,
    ChainIdSolver,
    ChainIdSolver_RNE,
    ChainIkSolverPos,
    ChainIkSolverPos_LMA,
    ChainIkSolverPos_NR,
    ChainIkSolverPos_NR_JL,
    ChainIkSolverVel,
    ChainIkSolverVel_pinv,
    ChainIkSolverVel_pinv_givens,
    ChainIkSolverVel_pinv_nso,
    ChainIkSolverVel_wdls,
    ChainJntToJacDotSolver,
    ChainJntToJacSolver,
    SolverI,
)

#: the KDL version whose behaviour this follows (PyKDL.__version__)
__version__ = "1.5.1"

__all__ = [
    "Add", "Chain", "ChainDynParam", "ChainFkSolverPos", "ChainFkSolverPos_recursive",
    "ChainFkSolverVel", "ChainFkSolverVel_recursive", "ChainIdSolver", "ChainIdSolver_RNE",
    "ChainIkSolverPos", "ChainIkSolverPos_LMA", "ChainIkSolverPos_NR", "ChainIkSolverPos_NR_JL",
    "ChainIkSolverVel", "ChainIkSolverVel_pinv", "ChainIkSolverVel_pinv_givens",
    "ChainIkSolverVel_pinv_nso", "ChainIkSolverVel_wdls", "ChainJntToJacDotSolver",
    "ChainJntToJacSolver", "Divide", "Equal", "Frame", "FrameVel", "Jacobian", "JntArray",
    "JntArrayVel", "JntSpaceInertiaMatrix", "Joint", "Multiply", "MultiplyJacobian",
    "RigidBodyInertia", "Rotation", "RotationVel", "RotationalInertia", "Segment", "SetToZero",
    "SolverI", "Subtract", "Tree", "Twist", "TwistVel", "Vector", "VectorVel", "Wrench",
    "addDelta", "changeBase", "changeRefPoint", "diff", "doubleVel", "dot",
]
