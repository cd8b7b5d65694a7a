"""catkin.find_in_workspaces stand-in: a project's folders in the catkin workspaces
(minros.workspace.locate)."""

from catkin_pkg.packages import find_packages  # noqa: F401 - catkin's module has it too

from minros.workspace.locate import find_in_workspaces, get_source_paths, get_workspaces

__all__ = ["find_in_workspaces", "find_packages", "get_source_paths", "get_workspaces"]
