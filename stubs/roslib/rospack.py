"""roslib.rospack: rospack's dependency queries (minros.packages, in-process); rosstack's
are answered for the stacks of old rosbuild trees by rospkg."""

from __future__ import annotations

from typing import List

import rospkg

from minros.packages import ROSLibException, dependency_query, plugins, ros_package_path


def rospack_depends_on_1(pkg: str) -> List[str]:
    """Packages that depend directly on ``pkg``."""
    return dependency_query(pkg, reverse=True, direct=True)


def rospack_depends_on(pkg: str) -> List[str]:
    """Packages that depend on ``pkg``."""
    return dependency_query(pkg, reverse=True)


def rospack_depends_1(pkg: str) -> List[str]:
    """Packages ``pkg`` depends on directly."""
    return dependency_query(pkg, direct=True)


def rospack_depends(pkg: str) -> List[str]:
    """Packages ``pkg`` depends on."""
    return dependency_query(pkg)


def rospack_plugins(pkg: str) -> List[tuple]:
    """``(package, plugin)`` of the packages exporting a plugin for ``pkg``."""
    return plugins(pkg, "plugin")


def _rosstack(s: str, reverse: bool, direct: bool) -> List[str]:
    stacks = rospkg.RosStack(ros_paths=[str(p) for p in ros_package_path()])
    try:
        if reverse:
            return list(stacks.get_depends_on(s, implicit=not direct))
        return list(stacks.get_depends(s, implicit=not direct))
    except rospkg.ResourceNotFound:
        raise ROSLibException(f"[rosstack] Error: stack '{s}' not found") from None


def rosstack_depends_on(s: str) -> List[str]:
    return _rosstack(s, reverse=True, direct=False)


def rosstack_depends_on_1(s: str) -> List[str]:
    return _rosstack(s, reverse=True, direct=True)


def rosstack_depends(s: str) -> List[str]:
    return _rosstack(s, reverse=False, direct=False)


def rosstack_depends_1(s: str) -> List[str]:
    return _rosstack(s, reverse=False, direct=True)


python3 = True
