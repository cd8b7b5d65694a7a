"""rospy.impl.rosout: logging to /rosout (minros.rospy_internals.rosout)."""

from minros.rospy_internals.rosout import (  # noqa: F401
    RosOutHandler,
    init_rosout,
    load_rosout_handlers,
)
