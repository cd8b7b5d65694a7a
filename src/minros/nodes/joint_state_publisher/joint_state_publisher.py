"""joint_state_publisher (no GUI): the robot's movable joints on ``joint_states`` at ``~rate``
Hz, from ``robot_description`` and ``~source_list`` topics; see minros.joint_state_publisher."""

from __future__ import annotations

import sys
from typing import List, Optional

import minros
from minros.joint_state_publisher.publisher import JointStatePublisher
from minros.urdf_model import URDFError


def main(argv: Optional[List[str]] = None) -> int:
    argv = list(sys.argv if argv is None else argv)
    if any(a in ("-h", "--help") for a in minros.myargv(argv)[1:]):
        print(__doc__)
        return 0
    minros.init_node("joint_state_publisher", argv=argv)
    try:
        publisher = JointStatePublisher()
    except RuntimeError as exc:
        minros.logfatal(str(exc))
        return 1
    except URDFError as exc:
        minros.logfatal(f"joint_state_publisher: {exc}")
        return 1
    publisher.loop()
    return 0


if __name__ == "__main__":
    sys.exit(main())
