"""tf stand-in: ROS 1's first tf API and tf.transformations (behaviour in minros.tf)."""

from minros.tf.exceptions import (
    ConnectivityException,
    ExtrapolationException,
    LookupException,
)
from minros.tf.exceptions import TransformException as Exception  # noqa: A004 (tf's name)

from . import transformations
from .broadcaster import TransformBroadcaster
from .listener import Transformer, TransformerROS, TransformListener

__all__ = ["Exception", "ConnectivityException", "LookupException", "ExtrapolationException",
           "Transformer", "TransformerROS", "TransformListener", "TransformBroadcaster",
           "transformations"]
