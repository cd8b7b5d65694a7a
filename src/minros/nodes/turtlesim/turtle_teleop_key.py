"""``rosrun turtlesim turtle_teleop_key``: drive turtle1 with the arrow keys.

As teleop_turtle_key.cpp (noetic): node ``teleop_turtle``; publishes ``turtle1/cmd_vel`` (queue 1);
``scale_linear``/``scale_angular`` from the node's public namespace (default 2.0). The terminal
goes to non-canonical, no-echo mode (signals stay on, so Ctrl-C still works) and single bytes are
read: an arrow key sends ``ESC [ A..D``, and only the final letter matters, so typing capital
A/B/C/D moves the turtle too. Each arrow publishes one Twist; other keys publish nothing; ``q``
quits. The terminal settings are restored on every exit path.

When stdin is not a terminal, one line on stderr says so and bytes are read from it as they come
(end of input quits), so the tool can be scripted.
"""

from __future__ import annotations

import os
import select
import sys
from typing import Any, Callable, List

KEYCODE_RIGHT = 0x43
KEYCODE_LEFT = 0x44
KEYCODE_UP = 0x41
KEYCODE_DOWN = 0x42
KEYCODE_Q = 0x71

BANNER = ("Reading from keyboard\n"
          "---------------------------\n"
          "Use arrow keys to move the turtle. 'q' to quit.\n")

#: key byte -> (linear, angular) before scaling.
_MOTIONS = {
    KEYCODE_LEFT: (0.0, 1.0),
    KEYCODE_RIGHT: (0.0, -1.0),
    KEYCODE_UP: (1.0, 0.0),
    KEYCODE_DOWN: (-1.0, 0.0),
}


def key_to_motion(byte: int, l_scale: float = 2.0, a_scale: float = 2.0) -> Any:
    """(linear.x, angular.z) for a key byte; None for keys that publish nothing; 'quit' for q."""
    if byte == KEYCODE_Q:
        return "quit"
    motion = _MOTIONS.get(byte)
    if motion is None:
        return None
    return l_scale * motion[0], a_scale * motion[1]


def key_loop(read_byte: Callable[[], bytes], publish: Callable[[float, float], None],
             l_scale: float = 2.0, a_scale: float = 2.0) -> str:
    """Read bytes until 'q' or end of input; returns why it stopped ('quit' or 'eof')."""
    while True:
        data = read_byte()
        if not data:
            return "eof"
        motion = key_to_motion(data[0], l_scale, a_scale)
        if motion == "quit":
            return "quit"
        if motion is not None:
            publish(*motion)


def _scale(name: str, default: float) -> float:
    import rospy

    value = rospy.get_param(name, default)
    if isinstance(value, bool) or not isinstance(value, (int, float)):
        return default  # NodeHandle::param leaves the default on a type mismatch
    return float(value)


def main(argv: List[str] | None = None) -> int:
    import rospy
    from geometry_msgs.msg import Twist

    full_argv = list(sys.argv if argv is None else argv)
    extra = rospy.myargv(full_argv)[1:]
    if extra and extra[0] in ("-h", "--help"):
        sys.stdout.write("usage: turtle_teleop_key [remappings]\n"
                         "Drive turtle1 (turtle1/cmd_vel) with the arrow keys; 'q' quits.\n")
        return 0
    rospy.init_node("teleop_turtle", argv=full_argv)
    # Relative names: the public namespace of the node, as the C++ NodeHandle nh_.
    a_scale = _scale("scale_angular", 2.0)
    l_scale = _scale("scale_linear", 2.0)
    pub = rospy.Publisher("turtle1/cmd_vel", Twist, queue_size=1)

    def publish(linear: float, angular: float) -> None:
        twist = Twist()
        twist.linear.x = linear
        twist.angular.z = angular
        pub.publish(twist)

    fd = sys.stdin.fileno() if sys.stdin is not None else -1
    saved = None
    if fd >= 0 and os.isatty(fd):
        import termios

        saved = termios.tcgetattr(fd)
        raw = termios.tcgetattr(fd)
        raw[3] &= ~(termios.ICANON | termios.ECHO)  # lflag: byte at a time, no echo; ISIG kept
        raw[6][termios.VMIN] = 1
        raw[6][termios.VTIME] = 0
        termios.tcsetattr(fd, termios.TCSANOW, raw)
    else:
        sys.stderr.write("turtle_teleop_key: stdin is not a terminal; reading keys from it as they "
                         "arrive (end of input quits)\n")
        sys.stderr.flush()

    def restore() -> None:
        if saved is not None:
            import termios

            try:
                termios.tcsetattr(fd, termios.TCSANOW, saved)
            except Exception:  # terminal already gone (hangup): nothing left to restore
                pass

    rospy.on_shutdown(restore)
    sys.stdout.write(BANNER)
    sys.stdout.flush()

    def read_byte() -> bytes:
        # Poll so that a shutdown (Ctrl-C handled by the node, rosnode kill) ends the loop.
        while fd >= 0 and not rospy.is_shutdown():
            ready, _, _ = select.select([fd], [], [], 0.2)
            if ready:
                return os.read(fd, 1)
        return b""

    try:
        key_loop(read_byte, publish, l_scale, a_scale)
    except KeyboardInterrupt:
        pass
    except OSError as exc:
        sys.stderr.write(f"read(): {exc.strerror or exc}\n")
        return 1
    finally:
        restore()
        rospy.signal_shutdown("teleop done")
    return 0


if __name__ == "__main__":
    from minros.nodes.turtlesim import run_tool

    sys.exit(run_tool("turtle_teleop_key", main))
