"""joint_state_publisher's program."""
