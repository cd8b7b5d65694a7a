"""urdf_parser_py.urdf: minros.urdf_parser.urdf, which *is* this module (its module globals,
such as ``verbose``, are read and set through the module object)."""

import sys

from minros.urdf_parser import urdf as _module

sys.modules[__name__] = _module
