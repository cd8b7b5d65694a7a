"""roswtf.roslaunchwtf: checks of launch files (minros.cli.wtf)."""

from minros.cli.wtf import (  # noqa: F401
    roslaunch_duplicate_node_check,
    roslaunch_missing_pkgs_check,
)
from minros.cli.wtf import wtf_check_roslaunch_static as wtf_check_static  # noqa: F401
from roswtf.environment import paths  # noqa: E402, F401
from roswtf.rules import error_rule, warning_rule  # noqa: E402, F401
