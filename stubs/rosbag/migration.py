"""rosbag.migration stand-in: message migration rules and the migrator (minros.bag.migration)."""

from minros.bag.migration import *  # noqa: F401,F403
