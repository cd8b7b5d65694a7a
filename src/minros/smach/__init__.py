"""smach: hierarchical state machines (ROS's executive_smach), in plain Python.

smach needs no ROS: states return outcome strings, containers (StateMachine, Sequence,
Concurrence, Iterator) are states themselves, and userdata flows between states through
declared input and output keys with remapping. ``minros.smach_ros`` adds the ROS states
(actions, services, topics), the action server wrapper and the introspection server; the
ROS-named ``smach`` package in ``stubs/`` re-exports this one.

Modules: ``exceptions``, ``log`` (the replaceable loggers and shutdown check), ``state``
(State, CBState, cb_interface), ``user_data`` (UserData, Remapper, Const), ``container`` (the
construction stack and callbacks every container shares), ``state_machine`` (StateMachine,
Sequence), ``concurrence``, ``iterator``.
"""

from minros.smach.concurrence import Concurrence
from minros.smach.container import Container
from minros.smach.exceptions import (
    InvalidConstructionError,
    InvalidStateError,
    InvalidTransitionError,
    InvalidUserCodeError,
    SmachError,
)
from minros.smach.iterator import Iterator
from minros.smach.log import (
    is_shutdown,
    logdebug,
    logerr,
    loginfo,
    logwarn,
    set_loggers,
    set_shutdown_check,
)
from minros.smach.state import CBInterface, CBState, State, cb_interface, has_smach_interface
from minros.smach.state_machine import Sequence, StateMachine
from minros.smach.user_data import Const, Remapper, UserData, get_const

__all__ = [
    "set_loggers", "loginfo", "logwarn", "logerr", "logdebug",
    "SmachError", "InvalidTransitionError", "InvalidStateError", "InvalidConstructionError",
    "InvalidUserCodeError",
    "State", "CBState", "UserData", "Remapper", "Const", "get_const", "Container",
    "is_shutdown", "set_shutdown_check", "has_smach_interface", "cb_interface", "CBInterface",
    "StateMachine", "Sequence", "Concurrence", "Iterator",
]
