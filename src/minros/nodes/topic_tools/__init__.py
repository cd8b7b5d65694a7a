"""topic_tools' programs (``rosrun topic_tools relay|throttle|drop|mux|transform|...``)."""
