"""RobotStatePublisher: joint_states in, /tf and /tf_static out."""

from __future__ import annotations

import threading
from typing import Any, Dict, List, Optional

import minros
from geometry_msgs.msg import TransformStamped
from minros.robot_state_publisher.kinematics import joint_transform
from minros.tf.broadcaster import StaticTransformBroadcaster
from minros.urdf_model import Joint, parse_joints
from sensor_msgs.msg import JointState
from tf2_msgs.msg import TFMessage

__all__ = ["RobotStatePublisher"]


def _stamped(joint: Joint, position: float, stamp: Any) -> Any:
    (tx, ty, tz), (qx, qy, qz, qw) = joint_transform(joint, position)
    t = TransformStamped()
    t.header.stamp = stamp
    t.header.frame_id = joint.parent
    t.child_frame_id = joint.child
    t.transform.translation.x, t.transform.translation.y, t.transform.translation.z = tx, ty, tz
    t.transform.rotation.x, t.transform.rotation.y = qx, qy
    t.transform.rotation.z, t.transform.rotation.w = qz, qw
    return t


class RobotStatePublisher:
    """Publishes the transforms of ``description`` (URDF text)."""

    def __init__(self, description: str, publish_frequency: float = 50.0,
                 ignore_timestamp: bool = False, use_tf_static: bool = True) -> None:
        joints = parse_joints(description)
        self.moving: Dict[str, Joint] = {j.name: j for j in joints if j.moving}
        # floating and planar joints are published as fixed, as ROS's (through KDL) does
        self.fixed: List[Joint] = [j for j in joints if not j.moving]
        self.mimics: Dict[str, Joint] = {n: j for n, j in self.moving.items() if j.mimic}
        self.interval = 1.0 / publish_frequency if publish_frequency > 0 else 0.0
        self.ignore_timestamp = ignore_timestamp
        self.use_tf_static = use_tf_static
        self.last_published: Dict[str, float] = {}
        self.lock = threading.Lock()
        self.tf_pub = minros.Publisher("/tf", TFMessage, queue_size=100)
        self.static_broadcaster: Optional[StaticTransformBroadcaster] = None
        self.timer: Any = None
        if use_tf_static:
            self.static_broadcaster = StaticTransformBroadcaster()
            self.publish_fixed()
        elif self.fixed and self.interval > 0:
            self.timer = minros.Timer(minros.Duration.from_sec(self.interval),
                                      lambda event: self.publish_fixed())
        self.sub = minros.Subscriber("joint_states", JointState, self.on_joint_state,
                                     queue_size=10)

    def publish_fixed(self) -> None:
        """The fixed joints: once on /tf_static, or (use_tf_static false) on /tf stamped a
        little ahead, as ROS's does, so that lookups at the present time find them."""
        if self.static_broadcaster is not None:
            now = minros.Time.now()
            self.static_broadcaster.sendTransform([_stamped(j, 0.0, now) for j in self.fixed])
        else:
            stamp = minros.Time.now() + minros.Duration.from_sec(0.5)
            self.tf_pub.publish(TFMessage(transforms=[_stamped(j, 0.0, stamp) for j in self.fixed]))

    def on_joint_state(self, msg: Any) -> None:
        if len(msg.name) != len(msg.position):
            minros.logerr("Robot state publisher ignored an invalid JointState message")
            return
        stamp = msg.header.stamp
        now = stamp.to_sec()
        with self.lock:
            last = min((self.last_published.get(n, 0.0) for n in msg.name), default=0.0)
            if not self.ignore_timestamp and now < last + self.interval:
                return
            for name in msg.name:
                self.last_published[name] = now
        positions = dict(zip(msg.name, msg.position))
        for name, joint in self.mimics.items():
            mimic = joint.mimic
            if mimic is not None and mimic.joint in positions:
                positions[name] = positions[mimic.joint] * mimic.multiplier + mimic.offset
        transforms = [_stamped(self.moving[name], position, stamp)
                      for name, position in positions.items() if name in self.moving]
        if transforms:
            self.tf_pub.publish(TFMessage(transforms=transforms))
