"""smach stand-in: state machines (behaviour in minros.smach)."""

from minros.smach import *  # noqa: F401,F403
from minros.smach import __all__ as __all__  # noqa: PLC0414
from smach import (  # noqa: F401,E402 - the submodules code reaches as smach.state, ...
    concurrence,
    container,
    exceptions,
    iterator,
    log,
    sequence,
    state,
    state_machine,
    user_data,
    util,
)
