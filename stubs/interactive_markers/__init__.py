"""interactive_markers stand-in (see minros.interactive_markers)."""
