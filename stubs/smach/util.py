"""smach.util stand-in: the shutdown check and callback interfaces (see minros.smach)."""

from minros.smach.log import is_shutdown, set_shutdown_check  # noqa: F401
from minros.smach.state import CBInterface, cb_interface, has_smach_interface  # noqa: F401

__all__ = ["is_shutdown", "set_shutdown_check", "cb_interface", "has_smach_interface",
           "CBInterface"]
