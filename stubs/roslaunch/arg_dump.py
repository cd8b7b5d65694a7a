"""roslaunch.arg_dump: a launch file's arguments (minros.launch.rostools)."""

from minros.launch.rostools import dump_args, get_args  # noqa: F401
