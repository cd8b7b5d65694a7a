"""``rosrun tf tf_monitor [framea frameb]``: who publishes which frame, how often, how late.

As tf's program: every ~0.2 s it prints, for every frame (or the chain between the two frames
given), the publishing node and the average and maximum delay between a transform's stamp and
its arrival, then per broadcaster its rate and delays. Static transforms count as delay 0
under the broadcaster's name followed by "(static)".
"""

from __future__ import annotations

import sys
import threading
import time
from collections import deque
from typing import Any, Deque, Dict, List, Optional

from .tools import UsageError, cout, run_tool, tool_args

NAME = "tf_monitor"
#: samples kept per frame and per broadcaster (tf_monitor's 1000)
HISTORY = 1000


class Monitor:
    """The statistics of what arrives on /tf and /tf_static (no ROS here: tests feed it)."""

    def __init__(self) -> None:
        self.lock = threading.Lock()
        self.frame_authority: Dict[str, str] = {}
        self.delays: Dict[str, Deque[float]] = {}
        self.authority_delays: Dict[str, Deque[float]] = {}
        self.authority_arrivals: Dict[str, Deque[float]] = {}

    def record(self, transforms: List[Any], authority: str, is_static: bool, now: float) -> None:
        total = 0.0
        with self.lock:
            for t in transforms:
                child = t.child_frame_id
                self.frame_authority[child] = authority
                offset = 0.0 if is_static else now - t.header.stamp.to_sec()
                total += offset
                self.delays.setdefault(child, deque(maxlen=HISTORY)).append(offset)
            average = total / max(1, len(transforms))
            self.authority_delays.setdefault(authority, deque(maxlen=HISTORY)).append(average)
            self.authority_arrivals.setdefault(authority, deque(maxlen=HISTORY)).append(now)

    def frames_report(self, chain: Optional[List[str]] = None) -> str:
        lines = ["", "Frames:"]
        with self.lock:
            for frame in sorted(self.delays):
                if chain is not None and frame not in chain:
                    continue
                d = self.delays[frame]
                lines.append(f"Frame: {frame} published by {self.frame_authority.get(frame, '')} "
                             f"Average Delay: {cout(sum(d) / len(d))} Max Delay: {cout(max(0.0, *d))}")
        return "\n".join(lines) + "\n"

    def broadcasters_report(self) -> str:
        lines = []
        with self.lock:
            for authority in sorted(self.authority_delays):
                d = self.authority_delays[authority]
                arrivals = self.authority_arrivals[authority]
                frequency = len(arrivals) / max(1e-8, arrivals[-1] - arrivals[0])
                lines.append(f"Node: {authority} {cout(frequency)} Hz, Average Delay: "
                             f"{cout(sum(d) / len(d))} Max Delay: {cout(max(0.0, *d))}")
        return "".join(line + "\n" for line in lines)


def main(argv: Optional[List[str]] = None) -> int:
    import minros
    from tf2_msgs.msg import TFMessage

    from .exceptions import TransformException
    from .tf1 import TransformListener, strip_leading_slash

    full_argv = list(sys.argv if argv is None else argv)
    args = tool_args(full_argv)
    if args and args[0] in ("-h", "--help"):
        print("usage: tf_monitor [framea frameb]")
        return 0
    if len(args) not in (0, 2):
        raise UsageError("[ INFO] TF_Monitor: usage: tf_monitor framea frameb", 255)
    minros.init_node(NAME, argv=full_argv, anonymous=True)
    iterations = 0
    while minros.Time.now().is_zero() and not minros.is_shutdown():  # simulated time not yet
        iterations += 1
        if iterations > 10:
            minros.loginfo("tf_monitor waiting for time to be published")
            iterations = 0
        time.sleep(0.1)  # wall time: simulated time is not running yet
    framea, frameb = (strip_leading_slash(a) for a in args) if args else ("", "")
    listener = TransformListener()
    chain: Optional[List[str]] = None
    if args:
        sys.stdout.write(f"Waiting for transform chain to become available between {framea} "
                         f"and {frameb} ")
        sys.stdout.flush()
        while not minros.is_shutdown():
            try:
                listener.waitForTransform(framea, frameb, minros.Time(), minros.Duration(1.0))
                break
            except TransformException:
                sys.stdout.write(".")
                sys.stdout.flush()
        print()
        try:
            chain = listener.chain(frameb, minros.Time(), framea, minros.Time(), frameb)
        except TransformException as exc:
            minros.logwarn(f"Transform Exception {exc}")
            return 0
    monitor = Monitor()

    def callback(msg: Any, is_static: bool) -> None:
        authority = msg._connection_header.get("callerid", "") if getattr(
            msg, "_connection_header", None) else ""
        monitor.record(msg.transforms, authority + ("(static)" if is_static else ""), is_static,
                       minros.get_time())

    minros.Subscriber("tf", TFMessage, callback, False, queue_size=100)
    minros.Subscriber("tf_static", TFMessage, callback, True, queue_size=100)
    max_diff = avg_diff = 0.0
    counter = 0
    while not minros.is_shutdown():
        counter += 1
        if chain is not None:
            try:
                stamp = listener._buffer.lookup_transform(framea, frameb, minros.Time()).header.stamp
                diff = minros.get_time() - stamp.to_sec()
                avg_diff = 0.01 * diff + 0.99 * avg_diff
                max_diff = max(max_diff, diff)
            except TransformException:
                pass
        minros.sleep(0.01)
        if counter > 20:
            counter = 0
            if chain is not None:
                sys.stdout.write(f"\n\n\nRESULTS: for {framea} to {frameb}\n"
                                 f"Chain is: {' -> '.join(chain)}\n"
                                 f"Net delay     avg = {cout(avg_diff)}: max = {cout(max_diff)}\n")
            else:
                sys.stdout.write("\n\n\nRESULTS: for all Frames\n")
            sys.stdout.write(monitor.frames_report(chain))
            sys.stdout.flush()
            sys.stderr.write("\nAll Broadcasters:\n")
            sys.stderr.flush()
            sys.stdout.write(monitor.broadcasters_report())
            sys.stdout.flush()
    return 0


if __name__ == "__main__":
    sys.exit(run_tool(NAME, main))
