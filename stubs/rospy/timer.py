"""rospy.timer: Rate, Timer, TimerEvent and sleep (minros.rostime)."""

from minros.rostime import Rate, Timer, TimerEvent, sleep  # noqa: F401
