"""Stand-in for ROS's ``rosbag`` Python package: the Bag API of :mod:`minros.bag`."""

from minros.bag import *  # noqa: F401,F403
from minros.bag import __all__  # noqa: F401


def __getattr__(name: str):
    if name == "rosbagmain":  # the rosbag command, loaded when asked for
        from minros.cli.bag import rosbagmain

        return rosbagmain
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
