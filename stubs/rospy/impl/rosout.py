"""rospy.impl.rosout: logging to /rosout (minros.rospy_internals.rosout), with the names
rospy's module imports."""

from minros.client.rostime import Time  # noqa: F401
from minros.client.topics import Publisher, Subscriber  # noqa: F401
from minros.exceptions import ROSException  # noqa: F401
from minros.rospy_internals import core as _core
from minros.rospy_internals.names import get_caller_id  # noqa: F401
from minros.rospy_internals.registration import get_topic_manager  # noqa: F401
from minros.rospy_internals.rosout import (  # noqa: F401
    RosOutHandler,
    init_rosout,
    load_rosout_handlers,
)


def __getattr__(name: str) -> object:
    if name == "Log":  # rosgraph_msgs/Log, built on first use
        return _core.Log  # type: ignore[attr-defined]
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
