"""smach.sequence stand-in (see minros.smach.state_machine)."""

from minros.smach.state_machine import Sequence  # noqa: F401

__all__ = ["Sequence"]
