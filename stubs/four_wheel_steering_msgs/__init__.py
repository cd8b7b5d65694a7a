"""four_wheel_steering_msgs: message package stand-in provided by minros."""
