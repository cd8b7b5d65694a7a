"""rospy.msg: AnyMsg and the publish-argument convention (minros.client.topics)."""

from minros.client.topics import AnyMsg, args_kwds_to_message  # noqa: F401
