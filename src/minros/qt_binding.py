"""python_qt_binding: one import path for Qt whichever Python binding is installed, as ROS's
rqt plugins use it (``from python_qt_binding.QtWidgets import QWidget``, ``loadUi``).

The binding is chosen when the module is first imported: PyQt5, else PySide2 (ROS's order,
``pyqt`` then ``pyside``), then the Qt 6 bindings PyQt6 and PySide6 (whose API moved some
names: code written for ROS's Qt 5 may need changes there). ``sys.SELECT_QT_BINDING`` names
one binding and ``sys.SELECT_QT_BINDING_ORDER`` reorders them, as in ROS. Without any binding
the import fails with ImportError naming what to install: minros brings none of its own
(``pip install 'minros[qt]'`` installs PyQt5).
"""

from __future__ import annotations

import importlib
import os
import sys
from typing import Any, Callable, Dict, List, Optional, Sequence

__all__ = ["QT_BINDING", "QT_BINDING_MODULES", "QT_BINDING_VERSION", "loadUi", "select_binding"]

REQUIRED_MODULES = ["QtCore", "QtGui", "QtWidgets"]
OPTIONAL_MODULES = [
    "QtBluetooth", "QtDBus", "QtDesigner", "QtHelp", "QtLocation", "QtMultimedia",
    "QtMultimediaWidgets", "QtNetwork", "QNetworkAuth", "QtNfc", "QtOpenGL", "QtPositioning",
    "QtPrintSupport", "QtQml", "QtQuick", "QtQuickWidgets", "QtScript", "QtScriptTools",
    "QtSensors", "QtSerialPort", "QtSql", "QtSvg", "QtTest", "QtWebChannel", "QtWebEngine",
    "QtWebEngineCore", "QtWebEngineWidgets", "QtWebKitWidgets", "QtWebSockets", "QtX11Extras",
    "QtXml", "QtXmlPatterns",
]
#: binding name (ROS's names) -> the Python packages tried for it, in order
PACKAGES = {"pyqt": ["PyQt5", "PyQt6"], "pyside": ["PySide2", "PySide6"]}
DEFAULT_ORDER = ["pyqt", "pyside"]

QT_BINDING: Optional[str] = None
QT_BINDING_VERSION: Optional[str] = None
QT_BINDING_MODULES: Dict[str, Any] = {}
_load_ui: Optional[Callable[..., Any]] = None


def _register(name: str, module: Any) -> None:
    # ROS's helper makes each Qt module importable under its bare name too ("import QtCore")
    sys.modules[name] = module
    QT_BINDING_MODULES[name] = module


def _load(package: str) -> str:
    """Import ``package``'s Qt modules; its version string. ImportError if it is absent."""
    modules = {name: importlib.import_module(f"{package}.{name}") for name in REQUIRED_MODULES}
    for name in OPTIONAL_MODULES:
        try:
            modules[name] = importlib.import_module(f"{package}.{name}")
        except ImportError:
            pass
    core = modules["QtCore"]
    if package.startswith("PyQt"):
        # PySide's names, which rqt code uses with either binding
        core.Signal, core.Slot, core.Property = core.pyqtSignal, core.pyqtSlot, core.pyqtProperty
        version = core.PYQT_VERSION_STR
    else:
        core.pyqtSignal, core.pyqtSlot, core.pyqtProperty = core.Signal, core.Slot, core.Property
        version = importlib.import_module(package).__version__
    for name, module in modules.items():
        _register(name, module)
    return version


def _pyqt_load_ui(package: str) -> Callable[..., Any]:
    def load_ui(uifile: str, baseinstance: Any = None, custom_widgets: Any = None) -> Any:
        uic = importlib.import_module(f"{package}.uic")
        return uic.loadUi(uifile, baseinstance=baseinstance)

    return load_ui


def _pyside_load_ui(package: str) -> Callable[..., Any]:
    def load_ui(uifile: str, baseinstance: Any = None, custom_widgets: Any = None) -> Any:
        QUiLoader = importlib.import_module(f"{package}.QtUiTools").QUiLoader  # noqa: N806
        QMetaObject = importlib.import_module(f"{package}.QtCore").QMetaObject  # noqa: N806
        widgets = dict(custom_widgets or {})

        class Loader(QUiLoader):
            """Creates the top widget as ``baseinstance`` and sets each named child on it,
            as PyQt's uic.loadUi does."""

            def createWidget(self, class_name: str, parent: Any = None, name: str = "") -> Any:  # noqa: N802
                if baseinstance is not None and parent is None:
                    return baseinstance
                if class_name in widgets:
                    widget = widgets[class_name](parent)
                else:
                    widget = QUiLoader.createWidget(self, class_name, parent, name)
                if baseinstance is not None:
                    setattr(baseinstance, name, widget)
                return widget

        ui = Loader(baseinstance).load(uifile)
        QMetaObject.connectSlotsByName(ui)
        return ui

    return load_ui


def select_binding(name: Optional[str] = None, order: Optional[Sequence[str]] = None) -> str:
    """Load the first binding of ``order`` (or the one ``name``d) that is installed; its
    name. ImportError, listing what was tried, when none is."""
    global QT_BINDING, QT_BINDING_VERSION, _load_ui
    order = list(order or DEFAULT_ORDER)
    if name:
        if name not in order:
            raise ImportError(f"Qt binding '{name}' is unknown")
        order = [name]
    tried: List[str] = []
    for binding in order:
        for package in PACKAGES.get(binding, []):
            try:
                version = _load(package)
            except ImportError as exc:
                tried.append(f"  {package}: {exc}")
                continue
            os.environ["QT_API"] = binding
            QT_BINDING, QT_BINDING_VERSION = binding, version
            _load_ui = _pyqt_load_ui(package) if binding == "pyqt" else _pyside_load_ui(package)
            return binding
        if binding not in PACKAGES:
            tried.append(f"  no loader for binding '{binding}'")
    raise ImportError(
        "Could not find Qt binding (looked for: " + ", ".join(f"'{b}'" for b in order) + "):\n"
        + "\n".join(tried) + "\npython_qt_binding needs a Qt binding for Python: "
        "pip install 'minros[qt]' (PyQt5), or PySide2/PySide6")


def loadUi(uifile: str, baseinstance: Any = None, custom_widgets: Any = None) -> Any:  # noqa: N802
    """Build the widgets of the Qt Designer file ``uifile`` (into ``baseinstance`` if
    given); ``custom_widgets`` maps class names to classes (PySide needs them)."""
    if _load_ui is None:
        select_binding(getattr(sys, "SELECT_QT_BINDING", None),
                       getattr(sys, "SELECT_QT_BINDING_ORDER", None))
    assert _load_ui is not None
    return _load_ui(uifile, baseinstance, custom_widgets)
