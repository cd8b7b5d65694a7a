"""rospy.impl.simtime: simulated time from /clock (minros.client.rostime, which init_node
starts on /use_sim_time)."""

from __future__ import annotations

from typing import Any

from minros import node as _node
from minros.client import rostime as _rostime
from minros.wire.masterapi import RemoteError

_USE_SIM_TIME = "/use_sim_time"


def _is_use_simtime() -> bool:
    """Whether the parameter server says /use_sim_time (False when it cannot be asked)."""
    try:
        return bool(_node.master().get_param(_USE_SIM_TIME))
    except (RemoteError, OSError):  # not set, or no master to ask
        return False


def _set_rostime_clock_wrapper(time_msg: Any) -> None:
    """A rosgraph_msgs/Clock message moves the node clock."""
    _rostime.on_clock(time_msg)


def _set_rostime_time_wrapper(time_msg: Any) -> None:
    """A roslib/Time message (ROS before Clock) moves the node clock."""
    _rostime._set_rostime(time_msg.rostime)


def init_simtime() -> bool:
    """On /use_sim_time: start the clock at 0 and follow /clock. True when it is used."""
    if not _is_use_simtime():
        return False
    from minros.client.topics import Subscriber
    from rosgraph_msgs.msg import Clock

    _rostime._set_rostime(_rostime.Time(0, 0))
    Subscriber("/clock", Clock, _set_rostime_clock_wrapper, queue_size=1)
    return True
