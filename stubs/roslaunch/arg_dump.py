"""roslaunch.arg_dump: a launch file's arguments (minros.launch.rostools)."""

from minros.launch.rostools import dump_args, get_args  # noqa: F401
from roslaunch.config import load_config_default  # noqa: E402, F401
from roslaunch.core import RLException  # noqa: E402, F401
