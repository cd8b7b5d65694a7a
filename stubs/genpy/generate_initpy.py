"""genpy.generate_initpy: the ``__init__.py`` of a folder of generated modules
(minros.msgs.pygen)."""

from minros.msgs.pygen import _module_name, write_module, write_modules  # noqa: F401
