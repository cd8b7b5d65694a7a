"""roswtf.model: findings (minros.cli.wtf)."""

from minros.cli.wtf import WtfError, WtfWarning  # noqa: F401
