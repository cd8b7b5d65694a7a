"""roslaunch.netapi: the roslaunch processes a master knows (minros.launch.rostools)."""

from minros.launch.rostools import NetProcess, get_roslaunch_uris, list_processes  # noqa: F401
