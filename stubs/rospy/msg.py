"""rospy.msg: AnyMsg and the publish-argument convention (minros.client.msg)."""

from minros.client.msg import AnyMsg, args_kwds_to_message  # noqa: F401
