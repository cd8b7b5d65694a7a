"""pr2_controllers_msgs: message package stand-in provided by minros."""
