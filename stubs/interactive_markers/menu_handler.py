"""interactive_markers.menu_handler stand-in (see minros.interactive_markers)."""

from minros.interactive_markers.menu_handler import *  # noqa: F401,F403
from visualization_msgs.msg import InteractiveMarkerFeedback, MenuEntry  # noqa: F401
