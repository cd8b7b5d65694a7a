"""interactive_markers: the server side of rviz's interactive markers, in pure Python.

``InteractiveMarkerServer`` speaks ROS's protocol on ``<topic_ns>/update_full`` (latched
``visualization_msgs/InteractiveMarkerInit``: every marker, with the server's sequence
number), ``<topic_ns>/update`` (``InteractiveMarkerUpdate``: the changes of each
``applyChanges()`` and a KEEP_ALIVE every 0.5 s) and ``<topic_ns>/feedback`` (what clients
such as rviz send back: poses, clicks, menu selections). ``MenuHandler`` builds a marker's
context menu and routes its selections. The ROS-named package in ``stubs/`` re-exports both.
"""

from minros.interactive_markers.menu_handler import EntryContext, MenuHandler
from minros.interactive_markers.server import InteractiveMarkerServer, MarkerContext, UpdateContext

__all__ = ["InteractiveMarkerServer", "MarkerContext", "UpdateContext", "MenuHandler",
           "EntryContext"]
