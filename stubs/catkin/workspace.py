"""catkin.workspace stand-in: the catkin workspaces on CMAKE_PREFIX_PATH
(minros.workspace.locate)."""

from minros.workspace.locate import CATKIN_MARKER_FILE, get_source_paths, get_workspaces

__all__ = ["CATKIN_MARKER_FILE", "get_source_paths", "get_workspaces"]
