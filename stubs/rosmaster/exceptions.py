"""rosmaster.exceptions."""

from minros.master import InternalException  # noqa: F401
