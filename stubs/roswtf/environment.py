"""roswtf.environment: checks of the ROS environment variables (minros.cli.wtf)."""

from minros.cli.wtf import (  # noqa: F401
    environment_errors,
    environment_warnings,
    invalid_url,
    paths,
    ros_master_uri_hostname,
    wtf_check_environment,
)
from roswtf.rules import error_rule, warning_rule  # noqa: E402, F401
