"""interactive_markers.interactive_marker_server stand-in (see minros.interactive_markers)."""

from minros.interactive_markers.server import *  # noqa: F401,F403
from std_msgs.msg import Header  # noqa: F401
from visualization_msgs.msg import (  # noqa: F401 - the protocol's messages
    InteractiveMarker,
    InteractiveMarkerFeedback,
    InteractiveMarkerInit,
    InteractiveMarkerPose,
    InteractiveMarkerUpdate,
)
