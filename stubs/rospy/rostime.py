"""rospy.rostime: Time, Duration and the ROS clock (minros.client.rostime)."""

from minros.client.rostime import (  # noqa: F401
    Duration,
    Time,
    get_rostime,
    get_time,
    is_wallclock,
)
