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
