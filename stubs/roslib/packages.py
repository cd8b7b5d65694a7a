"""roslib.packages: where packages, their resources and their programs are
(minros.packages, minros.workspace.executables; manifests through rospkg)."""

from __future__ import annotations

import os
from typing import Any, Callable, List

from minros import packages
from minros.packages import (  # noqa: F401
    MANIFEST_FILE,
    PACKAGE_FILE,
    InvalidROSPkgException,
    MultipleNodesException,
    ROSPkgException,
    get_dir_pkg,
    resource_file,
)
from minros.workspace.executables import find_executables

SRC_DIR = "src"
ROS_PACKAGE_PATH = "ROS_PACKAGE_PATH"
ROS_ROOT = "ROS_ROOT"


def get_pkg_dir(package: str, required: bool = True, ros_root: Any = None,
                ros_package_path: Any = None) -> str | None:
    """The folder of ``package``; InvalidROSPkgException (required) or None when missing."""
    return packages.get_pkg_dir(package, required)


def get_pkg_subdir(package: str, subdir: str, required: bool = True, env: Any = None) -> str | None:
    """``<package>/<subdir>``, created when ``required``."""
    folder = get_pkg_dir(package, required)
    if folder is None:
        return None
    path = os.path.join(folder, subdir)
    if required and not os.path.isdir(path):
        os.makedirs(path, exist_ok=True)
    return path


def list_pkgs_by_path(path: str, packages_: List[str] | None = None, cache: Any = None,
                      env: Any = None) -> List[str]:
    """Names of the packages below ``path``."""
    found = packages_ if packages_ is not None else []
    for name, folder in packages.list_packages(refresh=True).items():
        if os.path.abspath(str(folder)).startswith(os.path.abspath(path)) and name not in found:
            found.append(name)
    return found


def find_node(pkg: str, node_type: str, rospack: Any = None) -> List[str]:
    """The executable files named ``node_type`` in package ``pkg`` (as rosrun searches)."""
    return [str(p) for p in find_executables(pkg, node_type)]


def find_resource(pkg: str, resource_name: str, filter_fn: Callable[[str], bool] | None = None,
                  rospack: Any = None) -> List[str]:
    """Files named ``resource_name`` in package ``pkg``."""
    return packages.find_resource(pkg, resource_name, filter_fn)


PIPE = -1
