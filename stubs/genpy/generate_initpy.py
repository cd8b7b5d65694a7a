"""genpy.generate_initpy: the ``__init__.py`` of a folder of generated modules
(minros.msgs.pygen)."""

from genmsg.base import MsgGenerationException  # noqa: E402, F401
from minros.msgs.pygen import _module_name, write_module, write_modules  # noqa: F401
