"""tf2_web_republisher: message package stand-in provided by minros."""
