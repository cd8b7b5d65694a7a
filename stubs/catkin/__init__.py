"""catkin's run-time modules (catkin.workspace, catkin.find_in_workspaces) over
minros.workspace.locate; catkin's builder is not here: ``catkin_make`` is minros's."""
