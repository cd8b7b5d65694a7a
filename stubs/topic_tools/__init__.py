"""topic_tools: message package stand-in provided by minros."""
