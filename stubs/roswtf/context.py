"""roswtf.context: what roswtf checks and found (minros.cli.wtf)."""

from minros.cli.wtf import WtfContext, WtfException  # noqa: F401
from roswtf.model import WtfWarning  # noqa: E402, F401
