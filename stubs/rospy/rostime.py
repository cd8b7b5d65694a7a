"""rospy.rostime: Time, Duration and the ROS clock (minros.rostime)."""

from minros.rostime import (  # noqa: F401
    Duration,
    Time,
    get_rostime,
    get_time,
    is_wallclock,
)
