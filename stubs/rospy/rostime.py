"""rospy.rostime: Time, Duration and the ROS clock (minros.client.rostime)."""

from minros.client.rostime import (  # noqa: F401
    Duration,
    Time,
    _set_rostime,
    get_rostime,
    get_rostime_cond,
    get_time,
    is_rostime_initialized,
    is_wallclock,
    set_rostime_initialized,
    switch_to_wallclock,
    wallsleep,
)
