"""catkin workspaces (init, create_pkg, make) and the executables minros ships with its packages."""
