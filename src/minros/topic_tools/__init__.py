"""topic_tools: relay, throttle, drop, mux/demux and transform, in pure Python.

ROS's relay, throttle, drop, mux and demux are C++ programs over ``ShapeShifter``: they
forward a message's bytes without knowing its type, and advertise their output with the type,
md5 sum and definition of the first message they receive. ``shapeshifter`` does the same on
minros's ``AnyMsg``; ``policies`` holds the decisions (which message passes a throttle or a
drop, the mux's selection) as pure code; ``LazyTransport`` is the base class ROS's Python
topic_tools module offers. The programs are ``minros.nodes.topic_tools.*``, run as
``rosrun topic_tools relay ...`` and from launch files.
"""

from minros.topic_tools.lazy import LazyTransport

__all__ = ("LazyTransport",)
