"""tf2's exception classes (tf2_py's names), shared by the tf2_ros, tf2_py and tf stand-ins."""

from __future__ import annotations


class TransformException(Exception):
    """Base of every tf2 error (``tf2.TransformException``; ``tf.Exception`` in tf1)."""


class ConnectivityException(TransformException):
    """The two frames are in different trees: no chain of parents joins them."""


class LookupException(TransformException):
    """A frame does not exist, or the tree contains a loop."""


class ExtrapolationException(TransformException):
    """The requested time is outside the data buffered for some link of the chain."""


class InvalidArgumentException(TransformException):
    """An argument is malformed, such as a frame id that is empty or starts with '/'."""


class TimeoutException(TransformException):
    """A wait for a transform ran out of time."""


__all__ = ["TransformException", "ConnectivityException", "LookupException",
           "ExtrapolationException", "InvalidArgumentException", "TimeoutException"]
