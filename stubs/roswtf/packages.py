"""roswtf.packages: rules over the packages checked (minros.cli.wtfsource)."""

from minros.cli.wtfsource import (  # noqa: F401
    PACKAGE_FILE,
    cmakelists_package_valid,
    is_executable,
    manifest_msg_srv_export,
    manifest_rpath_flags,
    manifest_valid,
)
from minros.cli.wtfsource import packages_errors as errors  # noqa: F401
from minros.cli.wtfsource import packages_warnings as warnings  # noqa: F401
from minros.cli.wtfsource import wtf_check_packages as wtf_check  # noqa: F401
from roslib.packages import InvalidROSPkgException, get_pkg_dir  # noqa: E402, F401
from roswtf.environment import paths  # noqa: E402, F401
from roswtf.rules import error_rule, warning_rule  # noqa: E402, F401
