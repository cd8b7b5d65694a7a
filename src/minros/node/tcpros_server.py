"""A node's inbound server: accepts connections under the admission policy, reads each one's
header and hands it to whoever serves what the header names (rospy's TCPROSServer).

One server per node, with one listening socket per kind of peer and one accept loop for all:
the TCP port every ROS node has (protocol ``TCPROS``: topics and services), and, once a
subscriber asks for shared memory, an abstract Unix socket (protocol ``MINROSSHM``: nothing on
disk, reachable from this network namespace only). Each listening socket has its own admission
(``wire/admission``, the same limits): on TCP a peer is its address and ROS_ALLOWED_HOSTS
applies; on the Unix socket a peer is its process (SO_PEERCRED), always on this host.

The server knows no topics or services: ``dispatch(stream, header, conn, listener)`` (the
node's) takes the connection or returns why it cannot, and the refusal is sent here.
Admission bounds how many connections a peer holds, how long a header may trickle in and how
much memory requests take; a connection it evicts is shut down, and its thread cleans up.
"""

from __future__ import annotations

import logging
import os
import secrets
import socket
import threading
import time
import traceback
from typing import Any, Callable, Dict, List

from minros.wire import admission, sockets, tcpros, trace
from minros.wire.handshake import Rejected, refusal

__all__ = ["HEADER_TIMEOUT", "TCPROS_LIMITS", "Dispatch", "Listener", "TCPROSServer"]

#: time allowed to read an inbound connection header, however slowly it trickles in
HEADER_TIMEOUT = 10.0
#: the admission policy of the TCPROS server (wire/admission.py): handshakes and service
#: connections; a service request may be large (roscpp allows 1 GB), hence the budget
TCPROS_LIMITS = admission.Limits(max_connections=1024, head_timeout=HEADER_TIMEOUT,
                                 budget=1 << 30)
#: the listening socket of TCP (topics and services)
TCP = "TCPROS"
#: the abstract Unix socket of shared memory (topics)
UNIX = "MINROSSHM"

#: ``dispatch(stream, header, conn, listener) -> error text or None``: takes an inbound
#: connection that arrived on the listening socket of protocol ``listener`` (and owns its
#: stream from then on) or says why not; ``Rejected`` when it answered already
Dispatch = Callable[[Any, Dict[str, str], admission.Connection, str], "str | None"]

_logger = logging.getLogger("minros.node")
_rosout = logging.getLogger("rosout")


class Listener:
    """One listening socket of the server: its protocol, its admission, its connections."""

    def __init__(self, sock: socket.socket, protocol: str, policy: admission.Admission) -> None:
        self.sock = sock
        self.protocol = protocol
        self.admission = policy
        self.unix = sock.family == socket.AF_UNIX
        #: the Unix socket's abstract name (without the leading NUL)
        self.name = sock.getsockname()[1:].decode() if self.unix else ""
        self.inbound: Dict[int, socket.socket] = {}  # admission key -> inbound socket
        self.lock = threading.Lock()

    def peer(self, sock: socket.socket, addr: Any) -> str:
        """Who a connection is from, for the policy: an address, or a local process."""
        if not self.unix:
            return str(addr[0])
        creds = sockets.peer_credentials(sock)
        return f"pid {creds[0]}" if creds is not None else "unix"


class TCPROSServer:
    """The node's listening sockets and their accept threads; a thread per inbound
    connection until its header is read and dispatched (a service connection keeps it until
    it ends)."""

    def __init__(self, dispatch: Dispatch, shutting_down: Callable[[], bool],
                 allowed: Any = None, what: str = "",
                 limits: admission.Limits = TCPROS_LIMITS) -> None:
        self.dispatch = dispatch
        self.shutting_down = shutting_down
        self.what = what
        self.limits = limits
        #: the TCP socket's policy (the allow-list applies)
        self.admission = admission.Admission(limits, allowed, what=what)
        self.sock: socket.socket | None = None
        self.listeners: Dict[str, Listener] = {}
        self._closed = threading.Event()
        self._lock = threading.Lock()

    def start(self, host: str, port: int) -> None:
        """Listen on TCP at ``host:port`` (0: any free port)."""
        server = socket.socket(socket.AF_INET, socket.SOCK_STREAM)
        server.setsockopt(socket.SOL_SOCKET, socket.SO_REUSEADDR, 1)
        server.bind((host, port))
        server.listen(128)
        self.sock = server
        self._listen(Listener(server, TCP, self.admission), "minros-tcpros")

    def unix_name(self) -> str:
        """The abstract Unix socket's name, listening from the first call (OSError when the
        system has none)."""
        with self._lock:
            listener = self.listeners.get(UNIX)
            if listener is not None:
                return listener.name
            if self._closed.is_set():
                raise OSError("the node's server is closed")
            sock = socket.socket(socket.AF_UNIX, socket.SOCK_STREAM)
            try:
                sock.bind(f"\0minros-shm.{os.getpid()}.{secrets.token_hex(8)}")
                sock.listen(128)
            except OSError:
                sock.close()
                raise
            # its peers are processes of this host and network namespace: no allow-list
            listener = Listener(sock, UNIX, admission.Admission(self.limits, None,
                                                                what=self.what))
            self._listen(listener, "minros-shm")
            return listener.name

    def _listen(self, listener: Listener, name: str) -> None:
        self.listeners[listener.protocol] = listener
        threading.Thread(target=self._accept_loop, args=(listener, f"{name}-inbound"),
                         name=f"{name}-server", daemon=True).start()

    def listener(self, protocol: str) -> Listener | None:
        return self.listeners.get(protocol)

    @property
    def port(self) -> int:
        return self.sock.getsockname()[1] if self.sock is not None else 0

    def close(self) -> None:
        """Stop accepting, and end the inbound connections still being served (a service
        connection's thread blocks in recv without a timeout: the shutdown wakes it)."""
        self._closed.set()
        with self._lock:
            listeners = list(self.listeners.values())
        for listener in listeners:
            sockets.close(listener.sock)
            with listener.lock:
                keys = list(listener.inbound)
            self._evict(listener, keys)

    @staticmethod
    def refused(peer: str, reason: str) -> None:
        """A peer outside ROS_ALLOWED_HOSTS (one line per peer a minute, by the policy)."""
        _rosout.warning("%s", reason)

    def _accept_loop(self, listener: Listener, thread_name: str) -> None:
        """The one accept loop, for every listening socket."""
        adm = listener.admission
        while not self._closed.is_set():
            try:
                sock, addr = listener.sock.accept()
            except OSError:
                if self._closed.is_set():
                    return
                self._closed.wait(0.01)  # e.g. out of file descriptors: back off
                continue
            key = adm.new_key()
            try:
                local = sock.getsockname()
                victims = adm.admit(key, listener.peer(sock, addr),
                                    None if listener.unix else local[0], admission.ADMIT_GRACE)
            except admission.Refused as refused:
                if refused.report:
                    self.refused(str(addr), str(refused))
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
            self._evict(listener, victims)
            with listener.lock:
                listener.inbound[key] = sock
            try:
                threading.Thread(target=self._handle, args=(listener, sock, key),
                                 name=thread_name, daemon=True).start()
            except RuntimeError:  # cannot start a thread: drop this peer
                self._forget(listener, key)
                sockets.close(sock)

    def _evict(self, listener: Listener, keys: List[Any]) -> None:
        """Close inbound connections the admission policy chose to make room."""
        for key in keys:
            with listener.lock:
                sock = listener.inbound.get(key)
            if sock is not None:
                try:
                    sock.shutdown(socket.SHUT_RDWR)  # its thread sees the end and cleans up
                except OSError:
                    pass

    def _forget(self, listener: Listener, key: Any) -> None:
        with listener.lock:
            listener.inbound.pop(key, None)
        listener.admission.leave(key)

    def _handle(self, listener: Listener, sock: socket.socket, key: Any) -> None:
        """Read the connection header and dispatch the connection."""
        stream = trace.watch(sock, "accept", listener.protocol)
        conn = admission.Connection(listener.admission, key,
                                    lambda keys: self._evict(listener, keys))
        try:
            conn.reading()
            try:
                header = sockets.read_header(
                    stream, deadline=time.monotonic() + conn.limits.head_timeout,
                    charge=conn.charge)
                stream.settimeout(None)
            except (OSError, tcpros.HeaderError, admission.Refused) as exc:
                if not self.shutting_down() and not conn.evicted():
                    _rosout.warning("Inbound %s connection failed: %s",
                                    "shared-memory" if listener.unix else "TCP/IP", exc)
                sockets.close(stream)
                return
            conn.release()
            conn.busy()  # handed over: the service or topic owns it now
            try:
                error = self.dispatch(stream, header, conn, listener.protocol)
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
            self._forget(listener, key)
