"""smach's exceptions: each logs its message through smach's error logger when raised,
as ROS's smach does, so a failure inside a state machine thread is never silent."""

from __future__ import annotations

from minros.smach import log


class SmachError(Exception):
    """Base of smach's errors."""

    def __init__(self, message: str) -> None:
        log.logerr(f"{type(self).__name__}: {message}")
        super().__init__(message)


class InvalidTransitionError(SmachError):
    """An outcome bound to nothing, or a transition to an unknown state or outcome."""


class InvalidStateError(SmachError):
    """A state or container used in a way its specification does not allow."""


class InvalidUserCodeError(SmachError):
    """User code (a state's execute, a callback) raised, or broke the userdata contract."""


class InvalidConstructionError(SmachError):
    """A container built while it was not open."""


__all__ = ["SmachError", "InvalidTransitionError", "InvalidStateError", "InvalidUserCodeError",
           "InvalidConstructionError"]
