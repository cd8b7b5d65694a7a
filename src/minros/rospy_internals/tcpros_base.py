"""rospy.impl.tcpros_base: TCPROS transports, their protocols and a TCP server, as rospy has
them, speaking TCPROS through minros's codec (:mod:`minros.wire.tcpros`) and socket chores
(:mod:`minros.wire.sockets`).

A :class:`TCPROSTransport` carries one connection: :meth:`~TCPROSTransport.connect` dials a
peer and exchanges headers (its protocol's fields out, the peer's checked in),
:meth:`~TCPROSTransport.send_message` frames and sends one message,
:meth:`~TCPROSTransport.receive_once` returns the messages of the next frames and
:meth:`~TCPROSTransport.receive_loop` hands them to a callback until the connection ends. A
frame announcing more than minros's frame limit ends the connection instead of growing the
buffer. :class:`TCPServer` accepts connections for a handler in a thread of its own.
"""

from __future__ import annotations

import errno
import io
import logging
import socket
import struct
import threading
import time
from typing import Any, Callable, Dict, List, Optional, Tuple

from minros import node as _node
from minros import rosenv
from minros.exceptions import (
    DeserializationError,
    ROSInitException,
    ServiceException,
    TransportException,
    TransportInitError,
    TransportTerminated,
)
from minros.wire import sockets, tcpros

from .transport import BIDIRECTIONAL, Transport

DEFAULT_BUFF_SIZE = tcpros.DEFAULT_BUFF_SIZE
TCPROS = tcpros.TCPROS

_logger = logging.getLogger("rospy.tcpros")
_U32 = struct.Struct("<I")

__all__ = ["DEFAULT_BUFF_SIZE", "TCPROS", "TCPROSServer", "TCPROSTransport",
           "TCPROSTransportProtocol", "TCPServer", "TransportException", "TransportInitError",
           "TransportTerminated", "get_tcpros_server_address", "init_tcpros_server",
           "recv_buff", "start_tcpros_server"]


def recv_buff(sock: socket.socket, b: Any, buff_size: int) -> int:
    """Receive up to ``buff_size`` bytes into ``b``; their number (0 when nothing was ready on
    a non-blocking socket). TransportTerminated when the peer closed."""
    try:
        data = sock.recv(buff_size)
    except OSError as exc:
        if exc.errno in (errno.EAGAIN, errno.EWOULDBLOCK):
            return 0
        raise TransportTerminated("unable to receive data from sender, check sender's logs for details") from None
    if not data:
        raise TransportTerminated("unable to receive data from sender, check sender's logs for details")
    b.write(data)
    return len(data)


class TCPServer:
    """Accepts TCP connections on ``port`` (0: any) and calls ``inbound_handler(sock, addr)``
    for each, in the accept thread (rospy's contract: the handler hands the socket on)."""

    def __init__(self, inbound_handler: Callable[[socket.socket, Any], Any], port: int = 0) -> None:
        self.port = port
        self.addr: Optional[str] = None
        self.is_shutdown = False
        self.inbound_handler = inbound_handler
        self.server_sock: Optional[socket.socket] = None
        self.server_sock = self._create_server_sock()

    def _create_server_sock(self) -> socket.socket:
        ipv6 = rosenv.use_ipv6()
        sock = socket.socket(socket.AF_INET6 if ipv6 else socket.AF_INET, socket.SOCK_STREAM)
        sock.setsockopt(socket.SOL_SOCKET, socket.SO_REUSEADDR, 1)
        sock.bind((rosenv.get_bind_address(), self.port))
        self.addr, self.port = sock.getsockname()[0:2]
        sock.listen(128)
        return sock

    def start(self) -> None:
        threading.Thread(target=self.run, name=f"rospy-tcp-server:{self.port}", daemon=True).start()

    def run(self) -> None:
        while not self.is_shutdown:
            try:
                if self.server_sock is None:
                    break
                client, addr = self.server_sock.accept()
            except OSError:
                if self.is_shutdown:
                    break
                time.sleep(0.05)  # a transient accept error (EMFILE): do not spin
                continue
            if self.is_shutdown:
                client.close()
                break
            try:
                self.inbound_handler(client, addr)
            except Exception:
                _logger.exception("inbound connection handler failed")
                sockets.close(client)

    def get_full_addr(self) -> Tuple[str, int]:
        """``(host, port)`` as other nodes should reach this server."""
        return rosenv.get_host_name(), self.port

    def shutdown(self) -> None:
        self.is_shutdown = True
        sock, self.server_sock = self.server_sock, None
        if sock is not None:
            try:
                sock.shutdown(socket.SHUT_RDWR)  # wakes accept()
            except OSError:
                pass
            sock.close()


# ---------------------------------------------------------------------------------------------
# the node's TCPROS server: minros's node has one; these functions name it as rospy does

def init_tcpros_server(port: int = 0) -> None:
    """rospy creates its TCPROS server here; minros's node makes its own when it starts."""


def start_tcpros_server() -> None:
    """See :func:`init_tcpros_server`."""


def get_tcpros_server_address() -> Tuple[str, int]:
    """``(host, port)`` of this node's TCPROS server (the node must be initialised)."""
    return _node.get_tcpros_address()


class TCPROSServer:
    """rospy's TCPROS server object: here, a view of the node's server."""

    def __init__(self, port: int = 0) -> None:
        self.port = port

    def start_server(self) -> None:
        """The node's server starts with the node."""

    def get_address(self) -> Tuple[str, int]:
        return get_tcpros_server_address()

    def shutdown(self, reason: str = "") -> None:
        """The node's server stops with the node."""


# ---------------------------------------------------------------------------------------------
# transports

class TCPROSTransportProtocol:
    """What one side of a TCPROS connection sends in its header and reads from the wire."""

    def __init__(self, resolved_name: str, recv_data_class: Any, queue_size: Optional[int] = None,
                 buff_size: int = DEFAULT_BUFF_SIZE) -> None:
        self.resolved_name = resolved_name
        self.recv_data_class = recv_data_class
        self.queue_size = queue_size
        self.buff_size = buff_size
        self.direction = BIDIRECTIONAL

    def read_messages(self, b: Any, msg_queue: List[Any], sock: socket.socket) -> None:
        """Move the complete frames of ``b`` into ``msg_queue`` as messages."""
        from .msg import deserialize_messages

        deserialize_messages(b, msg_queue, self.recv_data_class, queue_size=self.queue_size)

    def get_header_fields(self) -> Dict[str, str]:
        """The fields of this side's connection header."""
        return {}


def _check_announced(b: io.BytesIO) -> None:
    """The frame the buffer starts with must fit minros's frame limit: a peer announcing more
    would otherwise make the buffer grow for as long as it sends."""
    if b.tell() >= 4:
        (size,) = _U32.unpack_from(b.getbuffer(), 0)
        if size > tcpros.DEFAULT_MAX_FRAME:
            raise TransportException(
                f"frame of {size} bytes exceeds the limit of {tcpros.DEFAULT_MAX_FRAME}")


class TCPROSTransport(Transport):
    """One TCPROS connection (topic or service), its socket and buffers."""

    transport_type = "TCPROS"

    def __init__(self, protocol: TCPROSTransportProtocol, name: str,
                 header: Optional[Dict[str, str]] = None) -> None:
        super().__init__(protocol.direction, name=name)
        if not name:
            raise TransportInitError("Unable to initialize transport: name is not set")
        # rospy's name for its protocol object (the seam's protocol name is transport_type)
        self.protocol: Optional[TCPROSTransportProtocol] = protocol  # type: ignore[assignment]
        self.socket: Optional[socket.socket] = None
        self.endpoint_id = "unknown"
        self.callerid_pub = "unknown"
        self.dest_address: Optional[Tuple[str, int]] = None  # for reconnection
        self.read_buff: Optional[io.BytesIO] = io.BytesIO()
        self.write_buff: Optional[io.BytesIO] = io.BytesIO()
        self.header = header  # type: ignore[assignment]  # rospy's: None until one is read
        self.is_latched = False
        self.latch: Any = None
        self._fileno: Optional[int] = None
        self.md5sum: Optional[str] = None
        self.type: Optional[str] = None
        self.local_endpoint = (None, None)
        self.remote_endpoint = (None, None)

    def get_transport_info(self) -> str:
        return (f"{self.transport_type} connection on port {self.local_endpoint[1]} to "
                f"[{self.remote_endpoint[0]}:{self.remote_endpoint[1]} on socket {self._fileno}]")

    def fileno(self) -> Optional[int]:
        return self._fileno

    def set_endpoint_id(self, endpoint_id: str) -> None:
        self.endpoint_id = endpoint_id

    def set_socket(self, sock: socket.socket, endpoint_id: str) -> None:
        """Adopt an accepted socket (its header already read by the server)."""
        if self.socket is not None:
            raise TransportInitError("socket already initialized")
        self.socket = sock
        self.endpoint_id = endpoint_id
        self._fileno = sock.fileno()
        self.local_endpoint = sock.getsockname()

    def connect(self, dest_addr: str, dest_port: int, endpoint_id: str,
                timeout: Optional[float] = None) -> None:
        """Dial ``dest_addr:dest_port`` and exchange headers; TransportInitError on failure."""
        if rosenv.get_address_override() == "localhost" and not rosenv.is_local_address(dest_addr):
            msg = (f"attempted to connect to non-local host [{dest_addr}] from a node launched "
                   "with ROS_HOSTNAME=localhost")
            _logger.warning(msg)
            self.close()
            raise TransportInitError(msg)
        self.endpoint_id = endpoint_id
        self.dest_address = (dest_addr, dest_port)
        try:
            sock = socket.create_connection((dest_addr, dest_port), timeout=timeout)
            self.socket = sock
            self._fileno = sock.fileno()
            self.write_header()
            self.read_header()
            self.local_endpoint = sock.getsockname()
            self.remote_endpoint = (dest_addr, dest_port)
        except TransportInitError:
            raise
        except Exception as exc:
            transient = isinstance(exc, socket.timeout) or getattr(exc, "errno", None) in (
                errno.ENETDOWN, errno.ENETUNREACH, errno.ENETRESET, errno.ECONNABORTED,
                errno.ETIMEDOUT, errno.EHOSTDOWN, errno.EHOSTUNREACH)
            if not transient:
                self.close()
            raise TransportInitError(str(exc)) from None

    def _validate_header(self, header: Dict[str, str]) -> None:
        self.header = header
        if "error" in header:
            raise TransportInitError(f"remote error reported: {header['error']}")
        for required in ("md5sum", "type"):
            if required not in header:
                raise TransportInitError(f"header missing required field [{required}]")
        self.type = header["type"]
        self.md5sum = header["md5sum"]
        self.callerid_pub = header.get("callerid", self.callerid_pub)
        self.is_latched = header.get("latching", "0") == "1"

    def write_header(self) -> None:
        """Send the protocol's header fields."""
        if self.socket is None or self.protocol is None:
            return
        data = tcpros.encode_header(self.protocol.get_header_fields())
        self.socket.sendall(data)
        self.stat_bytes += len(data)

    def read_header(self) -> None:
        """Read and check the peer's header (bounded in size, as every minros header read)."""
        if self.socket is None:
            return
        try:
            header = sockets.read_header(self.socket)
        except tcpros.HeaderError as exc:
            raise TransportInitError(str(exc)) from None
        except OSError as exc:
            raise TransportInitError(f"unable to read the connection header: {exc}") from None
        self._validate_header(header)

    def send_message(self, msg: Any, seq: int) -> None:
        """Serialize (Header.seq stamped) and send one message."""
        from .msg import serialize_message

        assert self.write_buff is not None
        serialize_message(self.write_buff, seq, msg)
        self.write_data(self.write_buff.getvalue())
        self.write_buff.seek(0)
        self.write_buff.truncate(0)

    def write_data(self, data: bytes) -> bool:
        if not self.socket:
            raise TransportInitError("TCPROS transport was not successfully initialized")
        if self.done:
            raise TransportTerminated("connection closed")
        try:
            self.socket.sendall(data)
        except OSError as exc:
            _logger.debug("[%s]: closing connection [%s]: %s", self.name, self.endpoint_id, exc)
            self.close()
            raise TransportTerminated(str(exc)) from None
        self.stat_bytes += len(data)
        self.stat_num_msg += 1
        return True

    def receive_once(self) -> List[Any]:
        """Block until at least one message has arrived; the messages read."""
        sock = self.socket
        if sock is None:
            raise TransportException("connection not initialized")
        b, protocol = self.read_buff, self.protocol
        if b is None or protocol is None:
            raise TransportTerminated("connection closed")
        msg_queue: List[Any] = []
        try:
            sock.setblocking(True)
            while not msg_queue and not self.done and not _node.is_shutdown():
                if b.tell() >= 4:
                    protocol.read_messages(b, msg_queue, sock)
                if not msg_queue:
                    _check_announced(b)
                    self.stat_bytes += recv_buff(sock, b, protocol.buff_size)
        except (TransportTerminated, ServiceException):
            raise
        except DeserializationError as exc:
            raise TransportException(f"receive_once[{self.name}]: DeserializationError {exc}") from None
        except Exception as exc:
            raise TransportException(f"receive_once[{self.name}]: unexpected error {exc}") from None
        self.stat_num_msg += len(msg_queue)
        for m in msg_queue:
            m._connection_header = self.header
        if self.is_latched and msg_queue:
            self.latch = msg_queue[-1]
        return msg_queue

    def _reconnect(self) -> None:
        if self.dest_address is None:
            raise ROSInitException("internal error with reconnection state: address not stored")
        interval = 0.5
        while self.socket is None and not self.done and not _node.is_shutdown():
            try:
                self.connect(self.dest_address[0], self.dest_address[1], self.endpoint_id,
                             timeout=30.0)
            except TransportInitError:
                self.socket = None
            if self.socket is None:
                interval = min(interval * 2, 30.0)
                _node.wait_for_shutdown(interval)

    def receive_loop(self, msgs_callback: Callable[[List[Any], Any], Any]) -> None:
        """Read messages and hand each batch to ``msgs_callback(msgs, self)`` until the
        connection ends (reconnecting after a broken frame) or the node shuts down."""
        try:
            while not self.done and not _node.is_shutdown():
                try:
                    if self.socket is None:
                        self._reconnect()
                        continue
                    msgs = self.receive_once()
                    if not self.done and not _node.is_shutdown():
                        msgs_callback(msgs, self)
                except TransportTerminated as exc:
                    _logger.debug("[%s] failed to receive incoming message: %s", self.name, exc)
                    break
                except TransportException:
                    sockets.close(self.socket)
                    self.socket = None
                except DeserializationError as exc:
                    _logger.error("[%s] error deserializing incoming request: %s", self.name, exc)
        finally:
            if not self.done:
                self.close()

    def close(self) -> None:
        if self.done:
            return
        sock = self.socket
        try:
            if sock is not None:
                try:
                    sock.shutdown(socket.SHUT_RDWR)
                except (OSError, AttributeError):  # closed already, or no real socket
                    pass
                sock.close()
        finally:
            self.socket = self.read_buff = self.write_buff = self.protocol = None
            super().close()
