"""``rosrun tf static_transform_publisher``: tf's version, repeating the transform on /tf.

    static_transform_publisher x y z yaw pitch roll frame_id child_frame_id period_in_ms
    static_transform_publisher x y z qx qy qz qw frame_id child_frame_id period_in_ms

As tf's program: every period the transform goes out on /tf stamped now + period (dated
ahead so that listeners can use it until the next one arrives).
"""

from __future__ import annotations

import sys
from typing import List, Optional

from .static_transform_publisher import NAME, WRONG_COUNT, transform_from_args
from .tools import UsageError, command_line, number, run_tool

USAGE = """A command line utility for manually sending a transform.
It will periodicaly republish the given transform.
Usage: static_transform_publisher x y z yaw pitch roll frame_id child_frame_id  period(milliseconds)
OR
Usage: static_transform_publisher x y z qx qy qz qw frame_id child_frame_id  period(milliseconds)

This transform is the transform of the coordinate frame from frame_id into the coordinate frame
of the child_frame_id.
"""


def main(argv: Optional[List[str]] = None) -> int:
    import minros

    from .broadcaster import TransformBroadcaster

    full_argv, args = command_line(argv, USAGE, (9, 10), WRONG_COUNT)
    period_ms = number(args[-1], "period(milliseconds)", NAME)
    if period_ms <= 0:
        raise UsageError(f"{NAME}: period(milliseconds) must be > 0, got {args[-1]}")
    transform = transform_from_args(args[:-1])
    if transform.header.frame_id == transform.child_frame_id:
        raise UsageError(f"[FATAL] target_frame and source frame are the same "
                         f"({transform.header.frame_id}, {transform.child_frame_id}) this cannot work", 1)
    minros.init_node(NAME, argv=full_argv, anonymous=True)
    broadcaster = TransformBroadcaster()
    period = minros.Duration.from_sec(period_ms / 1000.0)
    while not minros.is_shutdown():
        transform.header.stamp = minros.Time.now() + period
        broadcaster.sendTransform(transform)
        minros.sleep(period)
    return 0


if __name__ == "__main__":
    sys.exit(run_tool(NAME, main))
