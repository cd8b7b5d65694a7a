"""controller_manager_msgs: message package stand-in provided by minros."""
