"""urdf_parser_py.xml_reflection (and its ``core``; ``basics``, whose helpers minros keeps in
core): minros.urdf_parser.xml_reflection's modules, which *are* these, so that replacing
``xml_reflection.on_error`` or ``xml_reflection.core.on_error`` (as upstream's tests and tools
do) changes what the parser calls."""

import sys

from minros.urdf_parser import xml_reflection as _package
from minros.urdf_parser.xml_reflection import core as _core

sys.modules[__name__ + ".core"] = _core
sys.modules[__name__ + ".basics"] = _core
sys.modules[__name__] = _package
