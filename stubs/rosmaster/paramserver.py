"""rosmaster.paramserver: the parameter tree and its subscriptions (minros.master)."""

from minros.master import ParamDictionary, compute_param_updates  # noqa: F401
