"""tf2_web_republisher's program."""
