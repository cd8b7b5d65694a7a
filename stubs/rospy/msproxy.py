"""rospy.msproxy: MasterProxy (minros.node)."""

from minros.node import MasterProxy  # noqa: F401
