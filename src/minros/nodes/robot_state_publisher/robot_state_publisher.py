"""robot_state_publisher: the URDF in ``robot_description`` (found by searching up the
namespaces, as ROS's does) and ``joint_states`` in, /tf and /tf_static out. Parameters:
``~publish_frequency`` (50 Hz), ``~ignore_timestamp`` (false), ``~use_tf_static`` (true)."""

from __future__ import annotations

import sys
from typing import List, Optional

import minros
from minros.robot_state_publisher import RobotStatePublisher
from minros.urdf_model import URDFError


def main(argv: Optional[List[str]] = None) -> int:
    argv = list(sys.argv if argv is None else argv)
    if any(a in ("-h", "--help") for a in minros.myargv(argv)[1:]):
        print(__doc__)
        return 0
    minros.init_node("robot_state_publisher", argv=argv)
    key = minros.search_param("robot_description")
    description = minros.get_param(key) if key else None
    if not isinstance(description, str) or not description.strip():
        minros.logfatal("Could not find parameter robot_description on parameter server: set it "
                        "to the robot's URDF (e.g. <param name=\"robot_description\" "
                        "command=\"$(find xacro)/xacro robot.xacro\"/>)")
        return 1
    try:
        RobotStatePublisher(description,
                            publish_frequency=float(minros.get_param("~publish_frequency", 50.0)),
                            ignore_timestamp=bool(minros.get_param("~ignore_timestamp", False)),
                            use_tf_static=bool(minros.get_param("~use_tf_static", True)))
    except URDFError as exc:
        minros.logfatal(f"Failed to parse the robot description ({key}): {exc}")
        return 1
    minros.spin()
    return 0


if __name__ == "__main__":
    sys.exit(main())
