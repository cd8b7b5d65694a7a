"""roswtf.plugins: the rules other packages add to roswtf (minros.cli.wtfsource)."""

from minros.cli.wtfsource import load_plugins  # noqa: F401
