"""``rosrun tf2_ros static_transform_publisher``: publish one transform, latched, on /tf_static.

    static_transform_publisher x y z qx qy qz qw frame_id child_frame_id
    static_transform_publisher x y z yaw pitch roll frame_id child_frame_id
    static_transform_publisher /param_name

As tf2_ros's program: an anonymous node ``static_transform_publisher_...``, the transform
stamped now, sent once through a StaticTransformBroadcaster and kept latched until killed;
the same frame twice is refused. Unlike C's atof, a word where a number belongs is an error.
"""

from __future__ import annotations

import math
import sys
from typing import Any, List, Optional

from .tools import command_line, number, run_tool

NAME = "static_transform_publisher"
USAGE = """A command line utility for manually sending a transform.
Usage: static_transform_publisher x y z qx qy qz qw frame_id child_frame_id
OR
Usage: static_transform_publisher x y z yaw pitch roll frame_id child_frame_id
OR
Usage: static_transform_publisher /param_name

This transform is the transform of the coordinate frame from frame_id into the coordinate frame
of the child_frame_id.
"""
WRONG_COUNT = f"[ERROR] {NAME} exited due to not having the right number of arguments"


def transform_from_args(args: List[str]) -> Any:
    """The TransformStamped (stamp unset) that 8 or 9 command-line values describe."""
    from geometry_msgs.msg import TransformStamped

    from .transformations import quaternion_from_euler

    t = TransformStamped()
    names = ["x", "y", "z"]
    if len(args) == 9:
        names += ["qx", "qy", "qz", "qw"]
    else:
        names += ["yaw", "pitch", "roll"]
    values = [number(text, name, NAME) for text, name in zip(args, names)]
    tr = t.transform.translation
    tr.x, tr.y, tr.z = values[:3]
    r = t.transform.rotation
    if len(args) == 9:
        r.x, r.y, r.z, r.w = values[3:7]
    else:
        yaw, pitch, roll = values[3:6]
        r.x, r.y, r.z, r.w = (float(v) for v in quaternion_from_euler(roll, pitch, yaw))
    t.header.frame_id = args[-2]
    t.child_frame_id = args[-1]
    return t


def transform_from_param(data: Any) -> Any:
    """A TransformStamped from a parameter shaped like the message (None if incomplete)."""
    from geometry_msgs.msg import TransformStamped

    try:
        tr, rot = data["transform"]["translation"], data["transform"]["rotation"]
        t = TransformStamped()
        t.transform.translation.x, t.transform.translation.y, t.transform.translation.z = (
            float(tr["x"]), float(tr["y"]), float(tr["z"]))
        r = t.transform.rotation
        r.x, r.y, r.z, r.w = float(rot["x"]), float(rot["y"]), float(rot["z"]), float(rot["w"])
        t.header.frame_id = str(data["header"]["frame_id"])
        t.child_frame_id = str(data["child_frame_id"])
        return t
    except (KeyError, TypeError, ValueError):
        return None


def main(argv: Optional[List[str]] = None) -> int:
    import minros

    from .broadcaster import StaticTransformBroadcaster

    full_argv, args = command_line(argv, USAGE, (1, 8, 9), WRONG_COUNT)
    transform = transform_from_args(args) if len(args) != 1 else None  # bad numbers: no node
    minros.init_node(NAME, argv=full_argv, anonymous=True)
    if transform is None:
        param = args[0]
        minros.loginfo(f"Looking for TF in parameter: {param}")
        if not minros.has_param(param):
            minros.logfatal(f"Could not read TF from parameter server: {param}")
            return 255
        data = minros.get_param(param)
        transform = transform_from_param(data)
        if transform is None:
            minros.logfatal(f"Could not validate XmlRpcC for TF data: {data}")
            return 255
    if transform.header.frame_id == transform.child_frame_id:
        minros.logfatal(f"target_frame and source frame are the same ({transform.header.frame_id}, "
                        f"{transform.child_frame_id}) this cannot work")
        return 1
    r = transform.transform.rotation
    norm = math.sqrt(r.x * r.x + r.y * r.y + r.z * r.z + r.w * r.w)
    if abs(norm * norm - 1.0) >= 1e-2:
        minros.logwarn(f"the quaternion ({r.x} {r.y} {r.z} {r.w}) has length {norm:g}: listeners "
                       "will ignore this transform (TF_DENORMALIZED_QUATERNION); give a unit "
                       "quaternion or yaw pitch roll")
    transform.header.stamp = minros.Time.now()
    StaticTransformBroadcaster().sendTransform(transform)
    minros.loginfo(f"Spinning until killed publishing {transform.header.frame_id} to "
                   f"{transform.child_frame_id}")
    minros.spin()
    return 0


if __name__ == "__main__":
    sys.exit(run_tool(NAME, main))
