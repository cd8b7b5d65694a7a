"""tf.broadcaster stand-in (see minros.tf.tf1)."""

from minros.tf.tf1 import TransformBroadcaster  # noqa: F401
