"""xacro's program."""
