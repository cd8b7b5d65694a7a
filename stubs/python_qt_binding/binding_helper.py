"""python_qt_binding.binding_helper stand-in: chooses the Qt binding on import
(minros.qt_binding); ImportError, naming what to install, when none is installed."""

import sys

from minros import qt_binding

if qt_binding.QT_BINDING is None:
    qt_binding.select_binding(getattr(sys, "SELECT_QT_BINDING", None),
                              getattr(sys, "SELECT_QT_BINDING_ORDER", None))

from minros.qt_binding import (  # noqa: E402,F401
    QT_BINDING,
    QT_BINDING_MODULES,
    QT_BINDING_VERSION,
    loadUi,
)
