"""rospy.msproxy: MasterProxy (minros.client.msproxy)."""

from minros.client.msproxy import MasterProxy  # noqa: F401
