"""roswtf.stacks: rules over the stacks checked (minros.cli.wtfsource)."""

from minros.cli.wtfsource import is_executable, manifest_depends  # noqa: F401
from minros.cli.wtfsource import stacks_errors as errors  # noqa: F401
from minros.cli.wtfsource import stacks_warnings as warnings  # noqa: F401
from minros.cli.wtfsource import wtf_check_stacks as wtf_check  # noqa: F401
from roswtf.environment import paths  # noqa: E402, F401
from roswtf.rules import error_rule, warning_rule  # noqa: E402, F401
