"""rostest.rostest_parent: the launch parent of a .test file (minros.launch.rostestparent)."""

from minros.launch.rostestparent import ROSTestLaunchParent  # noqa: F401
from roslaunch.core import RLException, printlog_bold  # noqa: E402, F401
from rosmaster.master import Master  # noqa: E402, F401
from rospy import logwarn  # noqa: E402, F401
