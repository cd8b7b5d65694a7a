"""jsk_footstep_msgs: message package stand-in provided by minros."""
