"""rosmaster.exceptions."""

from minros.master.registrations import InternalException  # noqa: F401
