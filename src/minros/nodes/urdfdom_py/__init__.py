"""urdfdom_py's program (the ROS package that installs urdf_parser_py)."""
