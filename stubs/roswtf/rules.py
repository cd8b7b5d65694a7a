"""roswtf.rules: rules' answers as findings (minros.cli.wtf)."""

from minros.cli.wtf import error_rule, warning_rule  # noqa: F401
from roswtf.model import WtfError, WtfWarning  # noqa: E402, F401
