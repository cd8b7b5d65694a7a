"""roswtf.network: checks of the host's names and addresses (minros.cli.wtf)."""

from minros.cli.wtf import ip_check, ros_hostname_check, ros_ip_check  # noqa: F401
from minros.cli.wtf import network_errors as errors  # noqa: F401
from minros.cli.wtf import network_warnings as warnings  # noqa: F401
from minros.cli.wtf import wtf_check_network as wtf_check  # noqa: F401
from roswtf.rules import error_rule, warning_rule  # noqa: E402, F401
