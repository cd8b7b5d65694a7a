"""rosunit.pyunit: unittest cases run as a rosunit test."""

from rosunit import unitrun  # noqa: F401
