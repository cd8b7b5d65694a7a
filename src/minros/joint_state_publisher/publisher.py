"""joint_state_publisher's JointStatePublisher: reads the robot description and its parameters,
follows the ``source_list`` topics and publishes ``joint_states`` at ``rate`` Hz. The node is
this class's ``loop()``; joint_state_publisher_gui-style programs read ``free_joints`` and set
positions in it, and ``set_source_update_cb`` tells them when a source changed a joint."""

from __future__ import annotations

import threading
from typing import Any, Callable, List, Optional

import minros
from minros.joint_state_publisher.joints import JointTable
from sensor_msgs.msg import JointState

__all__ = ["JointStatePublisher", "get_param"]


def get_param(name: str, value: Any = None) -> Any:
    """``~name``, else ``name`` in the node's namespace, else ``value`` (joint_state_publisher's
    lookup)."""
    for key in ("~" + name, name):
        if minros.has_param(key):
            return minros.get_param(key)
    return value


class JointStatePublisher:
    """The robot's movable joints, their values, and the ``joint_states`` publisher.

    ``free_joints`` maps each joint that moves on its own to its entry (``min``, ``max``,
    ``zero``, ``position``/``velocity``/``effort`` as published, ``continuous``);
    ``dependent_joints`` maps mimic joints to ``parent``, ``factor``, ``offset``; ``joint_list``
    is the URDF's order. URDFError names a description that cannot be used."""

    def __init__(self, description_file: Optional[str] = None) -> None:
        description = get_param("robot_description") if description_file is None else description_file
        if description is None:
            raise RuntimeError("The robot_description parameter is required and not set.")
        self.use_mimic = bool(get_param("use_mimic_tags", True))
        self.use_small = bool(get_param("use_smallest_joint_limits", True))
        self.pub_def_positions = bool(get_param("publish_default_positions", True))
        self.pub_def_vels = bool(get_param("publish_default_velocities", False))
        self.pub_def_efforts = bool(get_param("publish_default_efforts", False))
        self.table = JointTable(description, zeros=get_param("zeros", {}) or {},
                                dependent_joints=get_param("dependent_joints", {}) or {},
                                use_mimic=self.use_mimic, use_small=self.use_small,
                                default_positions=self.pub_def_positions,
                                default_velocities=self.pub_def_vels,
                                default_efforts=self.pub_def_efforts)
        for warning in self.table.warnings:
            minros.logwarn(warning)
        self.free_joints = self.table.free
        self.dependent_joints = self.table.dependent
        self.joint_list: List[str] = self.table.order
        self.lock = threading.Lock()
        self.source_update_cb: Optional[Callable[[], None]] = None
        self.sources = [minros.Subscriber(source, JointState, self.source_cb)
                        for source in get_param("source_list", []) or []]
        self.pub = minros.Publisher("joint_states", JointState, queue_size=5)

    def source_cb(self, msg: Any) -> None:
        """Take the values a ``source_list`` topic gives for our free joints."""
        with self.lock:
            self.table.update_from(list(msg.name), list(msg.position), list(msg.velocity),
                                   list(msg.effort))
        if self.source_update_cb is not None:
            self.source_update_cb()

    def set_source_update_cb(self, user_cb: Optional[Callable[[], None]]) -> None:
        self.source_update_cb = user_cb

    def update(self, delta: float) -> None:
        """Move every free joint by ``delta``, turning back at its limits (``~delta``)."""
        with self.lock:
            self.table.sweep(delta)

    def message(self) -> Any:
        """The JointState the next cycle publishes, stamped now."""
        with self.lock:
            names, positions, velocities, efforts = self.table.message_lists()
        msg = JointState(name=names, position=positions, velocity=velocities, effort=efforts)
        msg.header.stamp = minros.Time.now()
        return msg

    def loop(self) -> None:
        """Publish at ``rate`` Hz (10 by default) until shutdown, sweeping by ``delta``."""
        rate = minros.Rate(float(get_param("rate", 10)))
        delta = float(get_param("delta", 0.0))
        while not minros.is_shutdown():
            if delta > 0:
                self.update(delta)
            msg = self.message()
            if msg.name:
                self.pub.publish(msg)
            try:
                rate.sleep()
            except minros.ROSInterruptException:
                break
            except minros.ROSTimeMovedBackwardsException:
                pass
