"""roslib.exceptions."""

from minros.packages import ROSLibException  # noqa: F401
