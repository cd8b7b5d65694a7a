"""rospy.timer: Rate, Timer, TimerEvent and sleep (minros.client.rostime)."""

from minros.client.rostime import Rate, Timer, TimerEvent, sleep  # noqa: F401
