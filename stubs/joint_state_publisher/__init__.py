"""joint_state_publisher stand-in: JointStatePublisher and get_param
(minros.joint_state_publisher); the program is ``rosrun joint_state_publisher
joint_state_publisher``."""

from minros.joint_state_publisher.publisher import JointStatePublisher, get_param  # noqa: F401
