"""roslib.exceptions."""


class ROSLibException(Exception):
    """Base of roslib's errors."""
