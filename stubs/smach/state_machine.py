"""smach.state_machine stand-in (see minros.smach.state_machine)."""

from minros.smach.state_machine import *  # noqa: F401,F403
