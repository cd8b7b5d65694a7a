"""python_qt_binding stand-in: ``from python_qt_binding.QtCore import QObject`` and
``from python_qt_binding import QtWidgets, loadUi`` with whichever Qt binding is installed
(minros.qt_binding: PyQt5, else PySide2, then the Qt 6 bindings)."""

import sys as _sys

from .binding_helper import QT_BINDING, QT_BINDING_MODULES, QT_BINDING_VERSION, loadUi  # noqa: F401

for _name, _module in QT_BINDING_MODULES.items():
    _sys.modules[f"{__name__}.{_name}"] = _module
    globals()[_name] = _module
