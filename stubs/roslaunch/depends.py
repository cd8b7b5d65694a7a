"""roslaunch.depends: the packages launch files need (minros.launch.rostools)."""

from minros.launch.rostools import RoslaunchDepsException, roslaunch_deps  # noqa: F401
