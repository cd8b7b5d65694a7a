"""roslaunch.param_dump: a launch file's parameters as YAML (minros.launch.rostools)."""

from minros.launch.rostools import dump_params  # noqa: F401
