"""rospy.msg: AnyMsg and the publish-argument convention (minros.topics)."""

from minros.topics import AnyMsg, args_kwds_to_message  # noqa: F401
