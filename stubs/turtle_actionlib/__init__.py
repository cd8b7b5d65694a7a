"""turtle_actionlib: message package stand-in provided by minros."""
