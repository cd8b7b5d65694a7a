"""nodelet's program (``rosrun nodelet nodelet manager|load|unload|standalone``)."""
