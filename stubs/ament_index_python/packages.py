"""ament_index_python.packages stand-in over minros's package lookup (see the package doc)."""

from __future__ import annotations

from minros import packages

__all__ = ["PackageNotFoundError", "get_package_share_directory", "get_package_prefix"]


class PackageNotFoundError(KeyError):
    """No package of that name on ROS_PACKAGE_PATH nor among minros's own."""

    def __init__(self, message: str, package_name: str | None = None) -> None:
        super().__init__(message)
        #: the package looked for (minros's xacro says "resource not found" with it)
        self.package_name = package_name


def get_package_share_directory(package_name: str, print_warning: bool = True) -> str:
    found = packages.find_package(package_name)
    if found is None:
        raise PackageNotFoundError(
            f"package '{package_name}' not found: is its folder on ROS_PACKAGE_PATH?",
            package_name)
    return str(found)


def get_package_prefix(package_name: str) -> str:
    """ROS 1 packages have no install prefix of their own: the package folder."""
    return get_package_share_directory(package_name)
