"""darknet_ros_msgs: message package stand-in provided by minros."""
