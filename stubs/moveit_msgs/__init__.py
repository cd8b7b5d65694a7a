"""moveit_msgs: message package stand-in provided by minros."""
