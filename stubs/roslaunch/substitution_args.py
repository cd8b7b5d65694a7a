"""roslaunch.substitution_args: $(...) substitutions (minros.launch.substitution)."""

from minros.launch.rosmodel import (  # noqa: F401
    ArgException,
    SubstitutionException,
    _anon,
    _arg,
    _collect_args,
    _dirname,
    _env,
    _find,
    _optenv,
    resolve_args,
)
from roslaunch.loader import convert_value  # noqa: E402, F401
