"""tf.tfwtf: roswtf's plugin for tf, run when something publishes ``/tf``.

It listens to ``/tf`` for a second, then checks what it heard: stamps more than 1 s away from
ROS time, a frame given a new parent, frames in a cycle, a frame published by two nodes, and
rotations that are not unit quaternions. The rules are pure functions over the messages heard
(``_msgs``: ``(message, receipt time, publisher)``), so they can be checked without a graph.
"""

from __future__ import annotations

import math
import time
from typing import Any, List, Optional, Tuple

from minros.cli.wtf import Rule, WtfContext, error_rule, warning_rule
from minros.tools.master import Master, MasterException

#: what the plugin heard: (tf message, ROS time at receipt, publishing node)
_msgs: List[Tuple[Any, Any, str]] = []
_MAX_DEPTH = 100


def _transforms() -> List[Tuple[Any, Any, str]]:
    return [(t, stamp, callerid) for m, stamp, callerid in _msgs for t in m.transforms]


def rostime_delta(ctx: WtfContext) -> List[str]:
    deltas: dict = {}
    for t, stamp, callerid in _transforms():
        secs = (t.header.stamp - stamp).to_sec()
        if abs(secs) > 1.0 and abs(secs) > abs(deltas.get(callerid, 0.0)):
            deltas[callerid] = secs
    return [f"receiving transform from [{k}] that differed from ROS time by {v}s"
            for k, v in deltas.items()]


def reparenting(ctx: WtfContext) -> List[str]:
    errors: List[str] = []
    parents: dict = {}
    for t, _stamp, callerid in _transforms():
        frame, parent = t.child_frame_id, t.header.frame_id
        if frame in parents and parents[frame] != parent:
            msg = f"reparenting of [{frame}] to [{parent}] by [{callerid}]"
            if msg not in errors:
                errors.append(msg)
        parents[frame] = parent
    return errors


def cycle_detection(ctx: WtfContext) -> List[str]:
    parents = {t.child_frame_id: t.header.frame_id for t, _s, _c in _transforms()}
    errors = []
    for frame in parents:
        chain, current = [], frame
        for _ in range(_MAX_DEPTH + 2):
            chain.append(current)
            if current not in parents:
                break
            current = parents[current]
            if current == frame:
                errors.append(f"Frame {frame} is in a loop. It's loop has elements:\n"
                              + " -> ".join(chain))
                break
    return errors


def multiple_authority(ctx: WtfContext) -> List[str]:
    errors: List[str] = []
    authority: dict = {}
    for t, _stamp, callerid in _transforms():
        frame = t.child_frame_id
        if frame in authority and authority[frame] != callerid:
            msg = (f"node [{callerid}] publishing transform [{frame}] with parent "
                   f"[{t.header.frame_id}] already published by node [{authority[frame]}]")
            if msg not in errors:
                errors.append(msg)
        authority[frame] = callerid
    return errors


def no_msgs(ctx: WtfContext) -> bool:
    return not _msgs


def not_normalized(ctx: WtfContext) -> List[str]:
    errors = []
    for t, _stamp, _callerid in _transforms():
        q = t.transform.rotation
        length = math.sqrt(q.x * q.x + q.y * q.y + q.z * q.z + q.w * q.w)
        if math.fabs(length - 1) > 1e-6:
            errors.append(f"rotation from [{t.header.frame_id}] to [{t.child_frame_id}] is not "
                          f"unit length, {length}")
    return errors


tf_warnings: List[Rule] = [
    (no_msgs, "No tf messages"),
    (rostime_delta, "Received out-of-date/future transforms:"),
    (not_normalized, "Received non-normalized rotation in transforms:"),
]
tf_errors: List[Rule] = [
    (reparenting, "TF re-parenting contention:"),
    (cycle_detection, "TF cycle detection::"),
    (multiple_authority, "TF multiple authority contention:"),
]


def _tf_handle(msg: Any) -> None:
    import minros

    header = getattr(msg, "_connection_header", None) or {}
    _msgs.append((msg, minros.get_rostime(), header.get("callerid", "unknown")))


def is_tf_active(master_uri: Optional[str] = None) -> bool:
    """Whether the master lists a publisher of ``/tf``."""
    try:
        topics = Master("/tfwtf", master_uri=master_uri, timeout=3.0).getPublishedTopics("/")
    except (MasterException, OSError):
        return False
    return any(name == "/tf" for name, _type in topics)


def roswtf_plugin_online(ctx: WtfContext, listen: float = 1.0) -> None:
    """Listen to /tf for ``listen`` seconds (as a node of this process, initialised here if
    it is not one yet), then run the rules into ``ctx``."""
    if not is_tf_active():
        return
    import minros
    from minros.node import is_initialized
    from tf2_msgs.msg import TFMessage

    print("running tf checks, this will take a second...")
    if not is_initialized():
        minros.init_node("roswtf", anonymous=True, disable_signals=True)
    sub = minros.Subscriber("/tf", TFMessage, _tf_handle)
    time.sleep(listen)  # the check is "what arrives in one second", as roswtf's
    sub.unregister()
    print("... tf checks complete")
    for rule in tf_warnings:
        warning_rule(rule, rule[0](ctx), ctx)
    for rule in tf_errors:
        error_rule(rule, rule[0](ctx), ctx)
