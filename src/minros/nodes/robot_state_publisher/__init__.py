"""robot_state_publisher's program."""
