"""Start-up hook: ``<pkg>.msg``/``<pkg>.srv`` of the packages ROS_PACKAGE_PATH names import in
any order, before rospy too, as a catkin devel space on PYTHONPATH makes them in ROS.

``minros_import_hook.pth`` (installed beside minros in site-packages) calls :func:`install`
when an interpreter starts. That appends one finder to the end of ``sys.meta_path``, after
every other finder, so it only ever sees imports nothing else could satisfy; it answers only
while ROS_PACKAGE_PATH is set, and only for packages found on it (minros's own message
packages have stand-ins already), by asking ``minros.msgs.importer``, which it imports on the
first such miss. Importing this module imports nothing but ``os`` and ``sys``; ``import minros``
itself still installs nothing.

Python asks the finder about every import that fails, at start-up too (Debian's sitecustomize
tries ``apport_python_hook`` in every interpreter; ``import rospy`` tries ``org``), and
answering "is this a package on ROS_PACKAGE_PATH?" means crawling it (450 ms for Debian's
/usr/share). So the crawl happens only for an import the finder serves (:func:`worth_a_look`):
``pkg.msg``, ``pkg.srv``, ``pkg.cfg[.X]``, and a bare ``pkg`` only while it is imported as the
parent of one of those, or when a folder ``pkg`` holding a manifest stands at the top of a
ROS_PACKAGE_PATH entry (a stat per entry). Any other name is declined without a look.
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
        if not worth_a_look(fullname, os.environ["ROS_PACKAGE_PATH"]):
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
#: the sub-modules minros.msgs.importer makes of a package (``pkg.cfg.X`` below ``cfg``)
_KINDS = ("msg", "srv", "cfg")
_IMPORTLIB = "<frozen importlib._bootstrap>"


def _served_shape(parts) -> bool:  # noqa: ANN001
    return (len(parts) == 2 and parts[1] in _KINDS) or (len(parts) == 3 and parts[1] == "cfg")


def _importing_below(top: str) -> bool:
    """Whether ``top`` is being imported as the parent of ``top.msg``, ``top.srv`` or
    ``top.cfg[.X]``: importlib imports a dotted name's parent first, from its frame of
    ``_find_and_load_unlocked(name, ...)`` for the dotted name, still on the stack."""
    frame = sys._getframe(2)
    while frame is not None:
        code = frame.f_code
        if code.co_name == "_find_and_load_unlocked" and code.co_filename == _IMPORTLIB:
            name = frame.f_locals.get("name")
            if isinstance(name, str) and name != top:
                return name.startswith(top + ".") and _served_shape(name.split("."))
        frame = frame.f_back
    return False


def worth_a_look(fullname: str, ros_package_path: str) -> bool:
    """Whether an import of ``fullname`` that nothing else could satisfy is one the finder may
    serve, decided without crawling: a name of the shapes it serves, or a bare name imported as
    the parent of one of them, or a bare name that is a folder with a ``package.xml`` (or
    rosbuild ``manifest.xml``) right under an entry of ``ros_package_path``. A bare name asked
    otherwise (``from pkg import msg`` of a package deeper in a workspace, before any import of
    ``pkg.msg``) is declined, as every failed import of a module would crawl."""
    parts = fullname.split(".")
    top = parts[0]
    if top in _STDLIB or top.startswith("_") or not top:
        return False
    if len(parts) > 1:
        return _served_shape(parts)
    if _importing_below(top):
        return True
    for root in ros_package_path.split(os.pathsep):
        if root and (os.path.isfile(os.path.join(root, top, "package.xml"))
                     or os.path.isfile(os.path.join(root, top, "manifest.xml"))):
            return True
    return False


def install() -> None:
    """Append the finder to ``sys.meta_path`` once (the .pth calls it at start-up)."""
    if not any(type(f).__name__ == "EnvironmentFinder" for f in sys.meta_path):
        sys.meta_path.append(EnvironmentFinder())
