"""roslaunch.depends: the packages launch files need (minros.launch.rostools)."""

from minros.launch.rostools import (  # noqa: F401
    RoslaunchDeps,
    RoslaunchDepsException,
    calculate_missing,
    parse_launch,
    print_deps,
    rl_file_deps,
    roslaunch_deps,
    roslaunch_deps_main,
)

NAME = "roslaunch-deps"

from rosgraph.names import load_mappings  # noqa: E402, F401
from roslaunch.loader import convert_value  # noqa: E402, F401
from roslaunch.substitution_args import resolve_args  # noqa: E402, F401
