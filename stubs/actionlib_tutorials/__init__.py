"""actionlib_tutorials: message package stand-in provided by minros."""
