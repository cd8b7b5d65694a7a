"""The master as a process: :class:`Master` (handler, callback pool and XML-RPC server) and
:func:`main`, the ``rosmaster --core`` command (``python -m minros.master``)."""

from __future__ import annotations

import argparse
import os
import signal
import sys
import threading
from typing import Callable, List

from minros import rosenv
from minros.master.callbacks import CALLBACK_TIMEOUT, CALLBACK_WORKERS, CallbackPool
from minros.master.handler import MasterHandler
from minros.master.log import configure_log_file
from minros.master.log import log as _log
from minros.signals import SignalWatch
from minros.wire import trace, xmlrpc

DEFAULT_MASTER_PORT = 11311


class Master:
    """A running master: handler, callback pool and XML-RPC server."""

    def __init__(self, port: int = DEFAULT_MASTER_PORT, host: str | None = None,
                 workers: int = CALLBACK_WORKERS, callback_timeout: float = CALLBACK_TIMEOUT,
                 hostname: str | None = None) -> None:
        """``host``: address to bind (default: ROS's rule from ROS_IP/ROS_HOSTNAME);
        ``hostname``: name advertised in the master URI (default: ROS_HOSTNAME/ROS_IP/host name)."""
        allowed = rosenv.allowed_hosts()  # first: ValueError naming a malformed entry
        self.hostname = hostname
        if host is None and hostname is not None:
            host = rosenv.get_bind_address(hostname)
        self.pool = CallbackPool(workers, callback_timeout)
        self.handler = MasterHandler(self.pool)
        self._stopped = threading.Event()
        # Stop once the reply to the shutdown call has reached the caller.
        self.handler._on_shutdown = lambda reason: xmlrpc.after_reply(self._stopped.set)
        bind = rosenv.get_bind_address() if host is None else host
        self.server = xmlrpc.XmlRpcServer(self.handler, bind, port,
                                          ipv6=":" in bind or rosenv.use_ipv6(), allowed=allowed,
                                          on_refused=_report_refusal, what="the master")
        self.uri = ""

    def start(self) -> Master:
        self.server.start()
        if self.hostname:
            self.uri = f"http://{self.hostname}:{self.server.port}/"
        else:
            self.uri = rosenv.create_local_xmlrpc_uri(self.server.port)
        self.handler._set_uri(self.uri)
        trace.set_node("/master", self.uri, self.uri)
        return self

    @property
    def port(self) -> int:
        return self.server.port

    def wait(self, timeout: float | None = None) -> bool:
        """Block until the master is stopped (by :meth:`stop` or the ``shutdown`` API)."""
        return self._stopped.wait(timeout)

    def ok(self) -> bool:
        return not self._stopped.is_set()

    def stop(self) -> None:
        self._stopped.set()
        self.server.shutdown()
        self.pool.stop()


def _report_refusal(peer: str, reason: str) -> None:
    """A peer outside ROS_ALLOWED_HOSTS: one line on the console and in master.log (at most
    one a minute per peer, by the admission policy)."""
    _log.warning("%s", reason)
    try:
        sys.stderr.write(f"[WARN] {reason}\n")
    except (OSError, ValueError):
        pass


def install_stop_signals(stop: Callable[[], None]) -> None:
    """SIGINT/SIGTERM stop the master cleanly (no traceback), from a thread of their own."""
    SignalWatch(lambda _signum: stop(), "master-signals").install((signal.SIGINT, signal.SIGTERM))


def main(argv: List[str] | None = None, prog: str = "minros master") -> int:
    """``rosmaster --core`` equivalent."""
    argv = sys.argv[1:] if argv is None else argv
    parser = argparse.ArgumentParser(prog=prog, description="Run a ROS master (no rosout).")
    parser.add_argument("--core", action="store_true", help="accepted for rosmaster compatibility")
    parser.add_argument("-p", "--port", type=int, default=DEFAULT_MASTER_PORT,
                        help=f"port to listen on (default {DEFAULT_MASTER_PORT})")
    parser.add_argument("-w", "--numworkers", type=int, default=CALLBACK_WORKERS,
                        help="threads making callbacks to nodes")
    parser.add_argument("-t", "--timeout", type=float, default=CALLBACK_TIMEOUT,
                        help="timeout of one callback to a node, in seconds")
    parser.add_argument("--master-logger-level", default=None, help="accepted and ignored")
    args, rest = parser.parse_known_args(argv)
    log_path = ""
    for extra in rest:
        if extra.startswith("__log:="):
            log_path = os.path.abspath(extra[len("__log:="):])
        else:
            parser.error(f"unrecognized arg: {extra}")
    if not 0 < args.port < 65536:
        parser.error(f"invalid port {args.port}")
    try:
        master = Master(args.port, workers=max(1, args.numworkers), callback_timeout=args.timeout)
    except ValueError as exc:
        print(f"{prog}: {exc}", file=sys.stderr)
        return 1
    try:
        master.start()
    except OSError as exc:
        print(f"{prog}: cannot listen on port {args.port}: {exc.strerror or exc}", file=sys.stderr)
        return 1
    configure_log_file(log_path or str(rosenv.ros_log_dir() / "master.log"))
    _log.info("Master initialized: port[%s], uri[%s]", master.port, master.uri)
    install_stop_signals(master._stopped.set)
    try:
        while not master.wait(1.0):
            pass
    finally:
        master.stop()
    return 0


