"""tf.transformations stand-in: [x, y, z, w] quaternions, 'sxyz' axes (see minros.tf.transformations)."""

from minros.tf.transformations import *  # noqa: F403
from minros.tf.transformations import _AXES2TUPLE, _EPS, _NEXT_AXIS, _TUPLE2AXES  # noqa: F401
