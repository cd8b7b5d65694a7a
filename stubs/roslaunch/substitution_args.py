"""roslaunch.substitution_args: $(...) substitutions (minros.launch.substitution)."""

from minros.launch.rosmodel import ArgException, SubstitutionException, resolve_args  # noqa: F401
