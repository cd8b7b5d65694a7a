"""tf2_ros' buffer_server node."""
