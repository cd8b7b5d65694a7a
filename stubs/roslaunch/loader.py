"""roslaunch.loader: what launch loading shares (minros.launch.rosmodel, substitution)."""

from minros.launch.rosmodel import LoadException  # noqa: F401
from minros.launch.substitution import convert_value  # noqa: F401
from rosgraph.names import canonicalize_name, is_legal_name, load_mappings, make_global_ns, ns_join  # noqa: E402, F401
from roslaunch.core import Param, RLException, RosbinExecutable  # noqa: E402, F401

PHASE_SETUP = "setup"
PRIV_NAME = "~"
