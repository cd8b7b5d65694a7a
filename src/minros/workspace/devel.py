"""A devel-space Python package in catkin's order: the workspace's first, then its underlays.

``catkin_make`` writes ``devel/lib/python3/dist-packages/<pkg>/__init__.py`` for every package
of the workspace with Python modules, messages or ``.cfg`` scripts; that file calls
:func:`overlay`. As a ROS devel space (its ``__init__`` extends ``__path__`` with every other
folder of the name), the package's modules are looked up in the devel folder (the message
stand-ins catkin_make wrote), then in the package's sources (``src/<pkg>``), then in the
package of the same name that the devel space hides: an underlay's devel space, or the Python
package minros ships (``actionlib``, ``turtlesim``, ...). So the workspace's package wins, and
what it lacks (a ``srv`` module, a library module) still comes from the underlay. The package's
own ``__init__.py`` runs when the sources have one; else the underlay's does, so a workspace
package that only adds messages to a library's name keeps the library's API.
"""

from __future__ import annotations

import importlib.machinery
import os
import sys
from typing import Any, Dict, List, Optional

#: the first line of the __init__.py catkin_make writes (what marks it as minros's)
MARK = "# minros catkin_make: the workspace's package first, then its underlay's"


def init_text(here: str, src: Optional[str]) -> str:
    """The ``__init__.py`` of the devel-space package at ``here`` (sources at ``src``)."""
    # binds no name: an underlay's file like this one runs in the same globals
    return (f"{MARK}\n"
            f"__import__('minros.workspace.devel', fromlist=['overlay']).overlay(\n"
            f"    globals(), {here!r}, {src!r})\n")


def _same(a: str, b: str) -> bool:
    try:
        return os.path.samefile(a, b)
    except OSError:
        return os.path.abspath(a) == os.path.abspath(b)


def underlay_spec(name: str, here: str) -> Any:
    """The spec the package ``name`` would have without the devel folder ``here``: the
    sys.path entries after its own, then the other finders (an editable install's)."""
    parent = os.path.dirname(os.path.abspath(here))
    entries: List[str] = [e for e in sys.path if isinstance(e, str)]
    position = next((i for i, e in enumerate(entries) if e and _same(e, parent)), None)
    after = entries[position + 1:] if position is not None else [
        e for e in entries if not (e and _same(e, parent))]
    spec = importlib.machinery.PathFinder.find_spec(name, after)
    if spec is not None:
        return spec
    for finder in sys.meta_path:
        if finder is importlib.machinery.PathFinder or not hasattr(finder, "find_spec"):
            continue
        try:
            spec = finder.find_spec(name, None)
        except Exception:  # noqa: BLE001 - a finder that cannot answer has nothing for us
            continue
        if spec is not None and spec.submodule_search_locations:
            return spec
    return None


def overlay(module_globals: Dict[str, Any], here: str, src: Optional[str]) -> None:
    """Make the module whose globals these are the workspace's package over its underlay."""
    path = module_globals["__path__"]
    if src and os.path.isdir(src) and src not in path:
        path.append(src)
    spec = underlay_spec(module_globals["__name__"], here)
    for location in (spec.submodule_search_locations or []) if spec is not None else []:
        if location not in path:
            path.append(location)
    init = os.path.join(src, "__init__.py") if src else None
    if init is None or not os.path.isfile(init):
        origin = getattr(spec, "origin", None) if spec is not None else None
        init = origin if origin and os.path.basename(origin) == "__init__.py" else None
    if init is not None:
        with open(init, encoding="utf-8") as source:
            code = compile(source.read(), init, "exec")
        exec(code, module_globals)  # noqa: S102 - the package's own __init__, as catkin's does
