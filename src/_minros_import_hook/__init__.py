"""Start-up hook: ``<pkg>.msg``/``<pkg>.srv`` of the packages ROS_PACKAGE_PATH names import in
any order, before rospy too, as a catkin devel space on PYTHONPATH makes them in ROS.

``minros_import_hook.pth`` (installed beside minros in site-packages) calls :func:`install`
when an interpreter starts. That appends one finder to the end of ``sys.meta_path``, after
every other finder, so it only ever sees imports nothing else could satisfy; it answers only
while ROS_PACKAGE_PATH is set, and only for packages found on it (minros's own message
packages have stand-ins already), by asking ``minros.msgs.importer``, which it imports on the
first such miss. Importing this module imports nothing but ``os`` and ``sys``; ``import minros``
itself still installs nothing.
"""

import _thread
import os
import sys

#: threads inside this finder now (an import it makes itself must not come back to it)
_busy = set()


class EnvironmentFinder:
    """The start-up finder (importlib's protocol; no ABC, whose import would cost start-up time)."""

    def find_spec(self, fullname, path=None, target=None):  # noqa: ANN001, ANN201
        me = _thread.get_ident()
        if not os.environ.get("ROS_PACKAGE_PATH") or me in _busy:
            return None
        if fullname.partition(".")[0] in _STDLIB:
            return None
        _busy.add(me)
        try:
            from minros.msgs.importer import ENVIRONMENT_FINDER

            return ENVIRONMENT_FINDER.find_spec(fullname, path, target)
        except Exception:  # noqa: BLE001 - minros half-installed: never break an import
            return None
        finally:
            _busy.discard(me)


_STDLIB = frozenset(getattr(sys, "stdlib_module_names", ())) | frozenset(sys.builtin_module_names)


def install() -> None:
    """Append the finder to ``sys.meta_path`` once (the .pth calls it at start-up)."""
    if not any(type(f).__name__ == "EnvironmentFinder" for f in sys.meta_path):
        sys.meta_path.append(EnvironmentFinder())
