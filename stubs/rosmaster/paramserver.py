"""rosmaster.paramserver: the parameter tree and its subscriptions (minros.master.params)."""

from minros.master.params import ParamDictionary, compute_param_updates  # noqa: F401
from rosgraph.names import canonicalize_name, is_global, is_private, ns_join  # noqa: E402, F401

GLOBALNS = "/"
SEP = "/"
