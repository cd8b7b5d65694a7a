"""``rosrun tf tf_echo source_frame target_frame [echo_rate]``: print a transform repeatedly.

As tf's program: the transform that takes data from target_frame into source_frame, at the
latest common time, printed with ``~precision`` decimals (default 3) at ``echo_rate`` Hz
(else ``~rate``, default 1); when the lookup fails, the error and the list of frames.
"""

from __future__ import annotations

import math
import sys
from typing import Any, List, Optional

from .tools import UsageError, command_line, number, run_tool

NAME = "tf_echo"
USAGE = """Usage: tf_echo source_frame target_frame [echo_rate]

This will echo the transform from the coordinate frame of the source_frame
to the coordinate frame of the target_frame.
Note: This is the transform to get data from target_frame into the source_frame.
Default echo rate is 1 if echo_rate is not given.
"""


def format_transform(stamp: Any, translation: List[float], rotation: List[float],
                     precision: int = 3) -> str:
    """tf_echo's block for one transform."""
    from .transformations import euler_from_quaternion

    roll, pitch, yaw = euler_from_quaternion(rotation)
    p = precision

    def row(values: List[float]) -> str:
        return "[" + ", ".join(f"{v:.{p}f}" for v in values) + "]"

    degrees = [v * 180.0 / math.pi for v in (roll, pitch, yaw)]
    return (f"At time {stamp.to_sec():.{p}f}\n"
            f"- Translation: {row(translation)}\n"
            f"- Rotation: in Quaternion {row(rotation)}\n"
            f"            in RPY (radian) {row([roll, pitch, yaw])}\n"
            f"            in RPY (degree) {row(degrees)}\n")


def main(argv: Optional[List[str]] = None) -> int:
    import minros

    from .exceptions import TransformException
    from .tf1 import TransformListener, strip_leading_slash

    full_argv, args = command_line(argv, USAGE, (2, 3))
    rate_hz = number(args[2], "echo_rate", NAME) if len(args) == 3 else None
    minros.init_node(NAME, argv=full_argv, anonymous=True)
    if rate_hz is None:
        rate_hz = float(minros.get_param("~rate", 1.0))
    if rate_hz <= 0.0:
        raise UsageError("Echo rate must be > 0.0", 255)
    precision = 3
    if minros.has_param("~precision"):
        precision = int(minros.get_param("~precision"))
        if precision < 1:
            raise UsageError("Precision must be > 0", 255)
        print(f"Precision default value was overriden, new value: {precision}", flush=True)
    source, target = args[0], args[1]
    listener = TransformListener()
    rate = minros.Rate(rate_hz)
    try:
        listener.waitForTransform(source, target, minros.Time(), minros.Duration(1.0))
    except TransformException:
        pass  # tf_echo reports failures in its loop
    while not minros.is_shutdown():
        try:
            msg = listener._buffer.lookup_transform(strip_leading_slash(source),
                                                    strip_leading_slash(target), minros.Time())
            t, r = msg.transform.translation, msg.transform.rotation
            sys.stdout.write(format_transform(msg.header.stamp, [t.x, t.y, t.z],
                                              [r.x, r.y, r.z, r.w], precision))
        except TransformException as exc:
            now = minros.Time.now()
            sys.stdout.write(f"Failure at {now.secs}.{now.nsecs:09d}\nException thrown:{exc}\n"
                             f"The current list of frames is:\n{listener.allFramesAsString()}\n")
        sys.stdout.flush()
        rate.sleep()
    return 0


if __name__ == "__main__":
    sys.exit(run_tool(NAME, main))
