"""rospy.msg: AnyMsg, the publish-argument convention and the framing of rospy's buffers
(minros.client.msg, minros.rospy_internals.msg)."""

from minros.rospy_internals.msg import (  # noqa: F401
    AnyMsg,
    args_kwds_to_message,
    deserialize_messages,
    serialize_message,
)
