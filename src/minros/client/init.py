"""``rospy.init_node``: the composition root of the client library.

It names the process's node and starts it (:mod:`minros.node`), then wires the pieces above
the node runtime to it in one readable sequence: the message import hook and the cv2.imshow
hook (as ``import rospy`` does), the signal handlers, the node clock (with a /clock subscription
on simulated time), and logging (log file, /rosout, logger services).
Nothing below this module reaches up to start these: the client library is a plain stack.
"""

from __future__ import annotations

import signal
import sys
import threading
from typing import Any, Dict, List

from minros import node
from minros.client import imshow, rosout_log, rostime, statistics
from minros.client.topics import Subscriber
from minros.msgs import install_import_hook
from minros.signals import SignalWatch

__all__ = ["init_node"]

_signal_chain: Dict[int, Any] = {}
_watch: List[SignalWatch] = []


def _on_signal(signum: int, frame: Any) -> None:
    _watch[0].handler(signum, frame)  # the shutdown itself runs outside the handler
    previous = _signal_chain.get(signum)
    if callable(previous) and previous is not signal.default_int_handler:
        try:
            previous(signum, frame)
        except KeyboardInterrupt:
            pass


def _register_signals() -> None:
    """SIGINT and SIGTERM shut the node down (then chain to handlers installed before)."""
    if _signal_chain or threading.current_thread() is not threading.main_thread():
        return
    _watch.append(SignalWatch(lambda signum: node.signal_shutdown(f"signal-{signum}"),
                              "minros-signal-shutdown"))
    for signum in (signal.SIGINT, signal.SIGTERM):
        try:
            _signal_chain[signum] = signal.signal(signum, _on_signal)
        except (ValueError, OSError):  # not the main interpreter
            pass


def init_node(name: str, argv: List[str] | None = None, anonymous: bool = False,
              log_level: int | None = None, disable_rostime: bool = False,
              disable_rosout: bool = False, disable_signals: bool = False,
              xmlrpc_port: int = 0, tcpros_port: int = 0) -> None:
    """Register this process as the node ``name`` with the master (rospy.init_node)."""
    # a program using `minros` as its rospy gets what `import rospy` installs
    install_import_hook()
    imshow.install()
    me = node.default_node()
    args_key = (name, list(sys.argv if argv is None else argv), anonymous, log_level,
                disable_rostime, disable_signals)
    if me.init_args is None and not disable_signals:
        _register_signals()
    if not me.init(name, argv, anonymous, xmlrpc_port=xmlrpc_port, tcpros_port=tcpros_port,
                   args_key=args_key):
        return  # already initialised with the same arguments
    use_sim_time = False
    if not disable_rostime:
        try:
            use_sim_time = bool(me.master.get_param("/use_sim_time"))
        except Exception:  # unset (MasterError), or the master is away: wall time
            use_sim_time = False
    rostime.start_node_time(use_sim_time)
    statistics.install()  # subscriptions read /enable_statistics when they are made
    if use_sim_time:
        from rosgraph_msgs.msg import Clock

        Subscriber("/clock", Clock, rostime.on_clock, queue_size=1)
    rosout_log.start_node_logging(me.caller_id, log_level, disable_rosout)
