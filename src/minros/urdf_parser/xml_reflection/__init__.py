"""urdf_parser_py's ``xml_reflection`` package: the names of ``core``, re-exported.

``on_error`` here is a name of its own: the URDF classes report through this one (upstream's
tests replace it with ``mock.patch('urdf_parser_py.xml_reflection.on_error', ...)``), while the
reader reports unknown tags through ``core.on_error``.
"""

from . import core
from .core import *  # noqa: F401,F403
from .core import __all__ as _core_all
from .core import on_error as on_error

__all__ = ["core", *_core_all]
