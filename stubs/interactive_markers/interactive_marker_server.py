"""interactive_markers.interactive_marker_server stand-in (see minros.interactive_markers)."""

from minros.interactive_markers.server import *  # noqa: F401,F403
