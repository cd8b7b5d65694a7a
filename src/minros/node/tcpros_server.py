"""A node's TCPROS server: accepts connections under the admission policy, reads each one's
header and hands it to whoever serves what the header names (rospy's TCPROSServer).

The server knows no topics or services: ``dispatch(stream, header, conn)`` (the node's) takes
the connection or returns why it cannot, and the refusal is sent here. Admission
(``wire/admission``) bounds how many connections a peer holds, how long a header may trickle
in and how much memory requests take; a connection it evicts is shut down, and its thread
cleans up.
"""

from __future__ import annotations

import logging
import socket
import threading
import time
import traceback
from typing import Any, Callable, Dict, List

from minros.wire import admission, sockets, tcpros, trace
from minros.wire.handshake import Rejected, refusal

__all__ = ["HEADER_TIMEOUT", "TCPROS_LIMITS", "Dispatch", "TCPROSServer"]

#: time allowed to read an inbound connection header, however slowly it trickles in
HEADER_TIMEOUT = 10.0
#: the admission policy of the TCPROS server (wire/admission.py): handshakes and service
#: connections; a service request may be large (roscpp allows 1 GB), hence the budget
TCPROS_LIMITS = admission.Limits(max_connections=1024, head_timeout=HEADER_TIMEOUT,
                                 budget=1 << 30)

#: ``dispatch(stream, header, conn) -> error text or None``: takes an inbound connection
#: (and owns its stream from then on) or says why not; ``Rejected`` when it answered already
Dispatch = Callable[[Any, Dict[str, str], admission.Connection], "str | None"]

_logger = logging.getLogger("minros.node")
_rosout = logging.getLogger("rosout")


class TCPROSServer:
    """One listening socket and its accept thread; a thread per inbound connection until its
    header is read and dispatched (a service connection keeps it until it ends)."""

    def __init__(self, dispatch: Dispatch, shutting_down: Callable[[], bool],
                 allowed: Any = None, what: str = "",
                 limits: admission.Limits = TCPROS_LIMITS) -> None:
        self.dispatch = dispatch
        self.shutting_down = shutting_down
        self.admission = admission.Admission(limits, allowed, what=what)
        self.sock: socket.socket | None = None
        self._closed = threading.Event()
        self._inbound: Dict[int, socket.socket] = {}  # admission key -> inbound socket
        self._inbound_lock = threading.Lock()

    def start(self, host: str, port: int) -> None:
        server = socket.socket(socket.AF_INET, socket.SOCK_STREAM)
        server.setsockopt(socket.SOL_SOCKET, socket.SO_REUSEADDR, 1)
        server.bind((host, port))
        server.listen(128)
        self.sock = server
        threading.Thread(target=self._accept_loop, args=(server,),
                         name="minros-tcpros-server", daemon=True).start()

    @property
    def port(self) -> int:
        return self.sock.getsockname()[1] if self.sock is not None else 0

    def close(self) -> None:
        """Stop accepting, and end the inbound connections still being served (a service
        connection's thread blocks in recv without a timeout: the shutdown wakes it)."""
        self._closed.set()
        sockets.close(self.sock)
        with self._inbound_lock:
            keys = list(self._inbound)
        self._evict(keys)

    @staticmethod
    def refused(peer: str, reason: str) -> None:
        """A peer outside ROS_ALLOWED_HOSTS (one line per peer a minute, by the policy)."""
        _rosout.warning("%s", reason)

    def _accept_loop(self, server: socket.socket) -> None:
        adm = self.admission
        while not self._closed.is_set():
            try:
                sock, addr = server.accept()
            except OSError:
                if self._closed.is_set():
                    return
                self._closed.wait(0.01)  # e.g. out of file descriptors: back off
                continue
            key = adm.new_key()
            try:
                victims = adm.admit(key, addr[0], sock.getsockname()[0])
            except admission.Refused as refused:
                if refused.report:
                    self.refused(addr[0], str(refused))
                sock.settimeout(1.0)
                try:  # the peer reads it where it expects the answer to its header
                    sock.sendall(refusal(str(refused)))
                except OSError:
                    pass
                sockets.close(sock)
                continue
            except OSError:  # the peer left already
                sockets.close(sock)
                continue
            self._evict(victims)
            with self._inbound_lock:
                self._inbound[key] = sock
            try:
                threading.Thread(target=self._handle, args=(sock, key),
                                 name="minros-tcpros-inbound", daemon=True).start()
            except RuntimeError:  # cannot start a thread: drop this peer
                self._forget(key)
                sockets.close(sock)

    def _evict(self, keys: List[Any]) -> None:
        """Close inbound connections the admission policy chose to make room."""
        for key in keys:
            with self._inbound_lock:
                sock = self._inbound.get(key)
            if sock is not None:
                try:
                    sock.shutdown(socket.SHUT_RDWR)  # its thread sees the end and cleans up
                except OSError:
                    pass

    def _forget(self, key: Any) -> None:
        with self._inbound_lock:
            self._inbound.pop(key, None)
        self.admission.leave(key)

    def _handle(self, sock: socket.socket, key: Any) -> None:
        """Read the connection header and dispatch the connection."""
        stream = trace.watch(sock, "accept")
        conn = admission.Connection(self.admission, key, self._evict)
        try:
            conn.reading()
            try:
                header = sockets.read_header(
                    stream, deadline=time.monotonic() + conn.limits.head_timeout,
                    charge=conn.charge)
                stream.settimeout(None)
            except (OSError, tcpros.HeaderError, admission.Refused) as exc:
                if not self.shutting_down() and not conn.evicted():
                    _rosout.warning("Inbound TCP/IP connection failed: %s", exc)
                sockets.close(stream)
                return
            conn.release()
            conn.busy()  # handed over: the service or topic owns it now
            try:
                error = self.dispatch(stream, header, conn)
            except Rejected as exc:  # refused by the handshake, which answered already
                if not self.shutting_down():
                    _rosout.warning("Could not process inbound connection: %s%s", exc, header)
                sockets.close(stream)
                return
            except Exception as exc:
                error = f"internal error: {exc}"
                _logger.error("inbound connection failed: %s", traceback.format_exc())
            if error is not None:
                if self.shutting_down():
                    error = "node shutting down"
                else:  # rospy's wording, header dict included
                    _rosout.warning("Could not process inbound connection: %s%s", error, header)
                try:
                    stream.sendall(refusal(error))
                except OSError:
                    pass
                sockets.close(stream)
        finally:
            # a topic connection lives on with its publication; a service one has ended
            self._forget(key)
