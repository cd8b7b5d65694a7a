"""python_qt_binding over the installed Qt binding (PyQt5 in the test environment): the Qt
modules under its names, PySide's Signal/Slot names on PyQt, loadUi of a Designer file into
a widget, the selection rules, and the ImportError without a binding; the same script run by
Debian's python_qt_binding gives the same answers."""

from __future__ import annotations

import json
import os
import subprocess
from pathlib import Path

import pytest

from support import PYTHON, REFERENCE_PYTHON, reference_env, require_reference

# each test starts a process (see the slow marker in pyproject.toml)
pytestmark = pytest.mark.slow

UI = """<?xml version="1.0" encoding="UTF-8"?>
<ui version="4.0">
 <class>Form</class>
 <widget class="QWidget" name="Form">
  <layout class="QVBoxLayout" name="layout">
   <item><widget class="QPushButton" name="go_button"><property name="text"><string>Go</string></property></widget></item>
   <item><widget class="QSlider" name="joint_slider"><property name="maximum"><number>100</number></property></widget></item>
  </layout>
 </widget>
</ui>
"""

SCRIPT = r'''
import json, sys
import python_qt_binding as q
from python_qt_binding import QtCore, loadUi
from python_qt_binding.QtCore import QObject, Signal, Slot
from python_qt_binding.QtWidgets import QApplication, QWidget
import QtWidgets  # ROS's helper registers the bare module names too

class Emitter(QObject):
    changed = Signal(int)

got = []
app = QApplication([])
emitter = Emitter()
emitter.changed.connect(got.append)
emitter.changed.emit(7)
widget = QWidget()
ui = loadUi(sys.argv[1], widget)
widget.joint_slider.setValue(42)
out = {"binding": q.QT_BINDING, "modules": sorted(set(q.QT_BINDING_MODULES) & {"QtCore", "QtGui", "QtWidgets", "QtTest"}),
       "same_module": q.QtCore is QtCore and QtWidgets is q.QtWidgets, "signal": got,
       "loaded_into": ui is widget, "slider": widget.joint_slider.value(),
       "button": widget.go_button.text(), "pyqtSignal": hasattr(QtCore, "pyqtSignal"),
       "Slot": Slot is not None}
print(json.dumps(out, sort_keys=True))
'''

NO_BINDING = r'''
import sys

sys.SELECT_QT_BINDING = "tk"
try:
    import python_qt_binding
except ImportError as exc:
    print(str(exc).splitlines()[0])
'''


def _run(python: str, args: list, env: dict) -> subprocess.CompletedProcess:
    return subprocess.run([python, "-c", *args], env=env, capture_output=True, text=True,
                          timeout=60)


def test_python_qt_binding_as_debians(tmp_path: Path) -> None:
    ui = tmp_path / "form.ui"
    ui.write_text(UI)
    env = dict(os.environ, QT_QPA_PLATFORM="offscreen", XDG_RUNTIME_DIR=str(tmp_path))
    ours = _run(PYTHON, [SCRIPT, str(ui)], env)
    assert ours.returncode == 0, ours.stderr
    mine = json.loads(ours.stdout.strip().splitlines()[-1])
    assert mine["binding"] == "pyqt" and mine["signal"] == [7] and mine["slider"] == 42
    assert mine["loaded_into"] and mine["button"] == "Go"
    refused = _run(PYTHON, [NO_BINDING], env)
    assert refused.stdout.strip() == "Qt binding 'tk' is unknown"
    require_reference()
    theirs = _run(REFERENCE_PYTHON, [SCRIPT, str(ui)], reference_env(env))
    assert theirs.returncode == 0, theirs.stderr
    assert mine == json.loads(theirs.stdout.strip().splitlines()[-1])
    assert _run(REFERENCE_PYTHON, [NO_BINDING], reference_env(env)).stdout == refused.stdout


def test_no_binding_installed_names_the_fix() -> None:
    """Where no Qt binding can be imported, the import fails naming what to install."""
    code = ("import sys\n"
            "for name in ('PyQt5', 'PyQt6', 'PySide2', 'PySide6'):\n"
            "    sys.modules[name] = None  # as if not installed\n"
            "try:\n"
            "    import python_qt_binding\n"
            "except ImportError as exc:\n"
            "    print(exc)\n")
    out = subprocess.run([PYTHON, "-c", code], capture_output=True, text=True, timeout=60)
    assert "Could not find Qt binding (looked for: 'pyqt', 'pyside')" in out.stdout
    assert "pip install 'minros[qt]'" in out.stdout
