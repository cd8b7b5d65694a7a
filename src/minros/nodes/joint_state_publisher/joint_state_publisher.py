"""joint_state_publisher (no GUI): the robot's movable joints on ``joint_states`` at ``~rate``
Hz, from ``robot_description`` and ``~source_list`` topics; see minros.joint_state_publisher."""

from __future__ import annotations

import sys
import threading
from typing import Any, List, Optional

import minros
from minros.joint_state_publisher import JointTable
from minros.urdf_model import URDFError
from sensor_msgs.msg import JointState


def _param(name: str, default: Any) -> Any:
    """``~name``, else ``name`` in the node's namespace, else the default (ROS's lookup)."""
    for key in ("~" + name, name):
        if minros.has_param(key):
            return minros.get_param(key)
    return default


def main(argv: Optional[List[str]] = None) -> int:
    argv = list(sys.argv if argv is None else argv)
    if any(a in ("-h", "--help") for a in minros.myargv(argv)[1:]):
        print(__doc__)
        return 0
    minros.init_node("joint_state_publisher", argv=argv)
    description = _param("robot_description", None)
    if not isinstance(description, str):
        minros.logfatal("The robot_description parameter is required and not set.")
        return 1
    try:
        table = JointTable(description, zeros=_param("zeros", {}) or {},
                           dependent_joints=_param("dependent_joints", {}) or {},
                           use_mimic=bool(_param("use_mimic_tags", True)),
                           use_small=bool(_param("use_smallest_joint_limits", True)),
                           default_positions=bool(_param("publish_default_positions", True)),
                           default_velocities=bool(_param("publish_default_velocities", False)),
                           default_efforts=bool(_param("publish_default_efforts", False)))
    except URDFError as exc:
        minros.logfatal(f"joint_state_publisher: {exc}")
        return 1
    for warning in table.warnings:
        minros.logwarn(warning)
    lock = threading.Lock()

    def on_source(msg: Any) -> None:
        with lock:
            table.update_from(list(msg.name), list(msg.position), list(msg.velocity),
                              list(msg.effort))

    for source in _param("source_list", []) or []:
        minros.Subscriber(source, JointState, on_source)
    pub = minros.Publisher("joint_states", JointState, queue_size=5)
    rate = minros.Rate(float(_param("rate", 10)))
    delta = float(_param("delta", 0.0))
    while not minros.is_shutdown():
        with lock:
            if delta > 0:
                table.sweep(delta)
            names, positions, velocities, efforts = table.message_lists()
        msg = JointState(name=names, position=positions, velocity=velocities, effort=efforts)
        msg.header.stamp = minros.Time.now()
        if names:
            pub.publish(msg)
        try:
            rate.sleep()
        except minros.ROSInterruptException:
            break
        except minros.ROSTimeMovedBackwardsException:
            pass
    return 0


if __name__ == "__main__":
    sys.exit(main())
