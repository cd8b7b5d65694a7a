"""Stand-in for roslib: load_manifest and the package, message, name and environment helpers
catkin-era code still imports (minros.packages, minros.msgs, minros.names, minros.rosenv)."""

from __future__ import annotations

from minros.msgs import install_import_hook

from . import exceptions, message, names, network, packages, rosenv  # noqa: F401
from .launcher import load_manifest

# code that uses roslib (load_manifest) imports the messages of packages on ROS_PACKAGE_PATH
install_import_hook()

__version__ = "1.7.0"
__all__ = ["load_manifest", "set_interactive", "is_interactive"]

_is_interactive = False


def set_interactive(interactive: bool) -> None:
    """Record that the program runs in an interactive shell (libraries may read it)."""
    global _is_interactive
    _is_interactive = interactive


def is_interactive() -> bool:
    return _is_interactive
