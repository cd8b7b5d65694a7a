"""rospy.impl.simtime: simulated time from /clock (minros.rospy_internals.simtime)."""

from minros.rospy_internals.simtime import (  # noqa: F401
    _is_use_simtime,
    _set_rostime_clock_wrapper,
    _set_rostime_time_wrapper,
    init_simtime,
)
