"""rosapi: message package stand-in provided by minros."""
