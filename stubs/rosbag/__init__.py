"""Stand-in for ROS's ``rosbag`` Python package: the Bag API of :mod:`minros.bag`."""

from minros.bag import *  # noqa: F401,F403
from minros.bag import __all__  # noqa: F401
