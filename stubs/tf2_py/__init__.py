"""tf2_py stand-in: tf2's BufferCore and exceptions, in pure Python (see minros.tf.core)."""

from minros.tf.core import BufferCore
from minros.tf.exceptions import (
    ConnectivityException,
    ExtrapolationException,
    InvalidArgumentException,
    LookupException,
    TimeoutException,
    TransformException,
)

__all__ = ["BufferCore", "TransformException", "ConnectivityException", "LookupException",
           "ExtrapolationException", "InvalidArgumentException", "TimeoutException"]
