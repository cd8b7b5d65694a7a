"""tf.listener stand-in (see minros.tf.tf1)."""

from minros.tf.tf1 import (  # noqa: F401
    Transformer,
    TransformerROS,
    TransformListener,
    strip_leading_slash,
    xyz_to_mat44,
    xyzw_to_mat44,
)
