"""actionlib_tools' programs (a headless axclient)."""
