"""genpy.generate_numpy: numpy dtypes and the numpy expressions of generated code
(minros.msgs.pygen)."""

from minros.msgs.pygen import NUMPY_DTYPE, pack_numpy, serialize, unpack_numpy  # noqa: F401
