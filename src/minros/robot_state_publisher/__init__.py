"""robot_state_publisher: a robot's link poses from its URDF and its joint positions.

``kinematics`` turns a joint and its position into the transform from its parent link to
its child link (pure); ``publisher.RobotStatePublisher`` subscribes to ``joint_states``,
publishes moving joints on /tf (stamped with the joint state's stamp) and fixed ones once on
the latched /tf_static, with ROS's parameters (``publish_frequency``, ``ignore_timestamp``,
``use_tf_static``). The program is ``rosrun robot_state_publisher robot_state_publisher``.
"""

from minros.robot_state_publisher.kinematics import joint_transform
from minros.robot_state_publisher.publisher import RobotStatePublisher

__all__ = ["joint_transform", "RobotStatePublisher"]
