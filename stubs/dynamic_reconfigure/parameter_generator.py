"""dynamic_reconfigure.parameter_generator: the rosbuild-era name of parameter_generator_catkin."""

from dynamic_reconfigure.parameter_generator_catkin import *  # noqa: F401,F403

LINEDEBUG = "//#line"
