"""cv_bridge.boost: where ROS's cv_bridge keeps its C++ extension (minros.cv_bridge has the
same functions in Python)."""
