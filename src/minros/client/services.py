"""ROS services over TCPROS: Service (server), ServiceProxy (client), wait_for_service.

Server side: ``Service`` registers with the master through ``minros.node.register_service``;
the node's TCPROS server hands every inbound connection whose header names this service to
:meth:`Service._handle_connection`, which runs the exchange on that socket in the connection's
thread:

    client -> header {service, md5sum, callerid[, persistent, probe, ...]}
    server -> header {service, type, md5sum, callerid}   (or {error} and close)
    client -> uint32 len + request            (nothing more for a probe)
    server -> uint8 ok + uint32 len + response | error string
    ... repeated while the connection is persistent

Client side: ``ServiceProxy`` looks the service up on the master for every call (unless
persistent), connects, exchanges headers, sends one request and reads one response. It works
without ``init_node`` (caller id ``/unnamed``). All error texts are rospy's.

The header codec, framing and response encoding are the pure functions of ``minros.wire.tcpros``;
this module only moves their bytes through sockets.
"""

from __future__ import annotations

import itertools
import logging
import socket
import struct
import sys
import threading
import time
import traceback
import warnings
import weakref
from types import TracebackType
from typing import Any, Callable, Dict

from minros import names, node
from minros.client.log import logerr, loginfo, logwarn, logwarn_throttle
from minros.client.msg import stamp_header
from minros.exceptions import (
    ROSException,
    ROSInterruptException,
    ServiceException,
    TransportException,
    TransportInitError,
    TransportTerminated,
)
from minros.msgs import reader_for
from minros.transport.tcpros_base import connect, negotiate
from minros.wire import admission, sockets, tcpros
from minros.wire.handshake import Handshake, Role, State
from minros.wire.masterapi import MasterError, RemoteError
from minros.wire.rosapi import ROSRPC, ParameterInvalid, parse_rosrpc_uri

__all__ = [
    "Service",
    "ServiceException",
    "ServiceProxy",
    "parse_rosrpc_uri",
    "wait_for_service",
]

DEFAULT_BUFF_SIZE = tcpros.DEFAULT_BUFF_SIZE
#: how often wait_for_service retries (rospy's interval)
WAIT_FOR_SERVICE_INTERVAL = 0.3
#: connect timeout of a service call; the response itself may take as long as the handler
CONNECT_TIMEOUT = 10.0
#: rospy's text when the peer closes the connection before a whole message arrived
_PEER_GONE = "unable to receive data from sender, check sender's logs for details"
#: a send waiting for a peer that reads nothing wakes up this often to notice node shutdown
#: (a wait for a request or a response blocks in recv: shutdown wakes it by closing the socket)
_POLL = 1.0
#: a send gives up on a peer that took no byte for this long (the bound topics.SYNC_SEND_TIMEOUT
#: puts on synchronous publishing). rospy's sendall waits forever; as long as the peer keeps
#: taking bytes, however slowly, a send goes on.
SEND_STALL_TIMEOUT = 60.0
#: frames up to this size are joined into one bytes object (one send call); larger ones keep
#: their big pieces and go out as scatter-gather, never copied into one buffer
_JOIN_LIMIT = 65536
#: serialized pieces smaller than this are joined with their neighbours (fewer buffers)
_SMALL_PART = 4096
#: a request's own buffer starts this small and doubles as its bytes arrive (a lying length
#: costs nothing: a server must not allocate what a client only announces)
_FIRST_CHUNK = 64 << 10
#: the ok byte that starts a successful service response
_OK = b"\x01"
_REQUEST_PREFIX = struct.Struct("<I").pack
_OK_PREFIX = struct.Struct("<BI").pack

_logger = logging.getLogger("rospy.service")


# --------------------------------------------------------------------------- sending

def _send_all(sock: socket.socket, data: Any) -> None:
    """Send ``data`` completely; give up at node shutdown or on a peer stalled for
    SEND_STALL_TIMEOUT seconds (TransportTerminated)."""
    sockets.send_all(sock, data, stall_timeout=SEND_STALL_TIMEOUT, stop=node.is_shutdown,
                     pace=_POLL)


# --------------------------------------------------------------------------- server

def _convert_return_to_response(response: Any, response_class: Any) -> Any:
    """Turn what a handler returned into a response message (rospy's rules and texts)."""
    if getattr(response, "_type", None) == response_class._type and hasattr(response, "serialize"):
        return response
    if type(response) is dict:
        try:
            return response_class(**response)
        except AttributeError as exc:
            raise ServiceException(f"handler returned invalid value: {exc}") from None
    if response is None:
        raise ServiceException("service handler returned None")
    if type(response) not in (list, tuple):
        try:
            return response_class(response)
        except TypeError as exc:
            raise ServiceException(f"handler returned invalid value: {exc}") from None
    try:
        return response_class(*response)
    except TypeError as exc:
        raise ServiceException(f"handler returned wrong number of values: {exc}") from None


def _default_error_handler(exc: BaseException, exc_type: type[BaseException] | None,
                           exc_value: BaseException | None, tb: TracebackType | None) -> None:
    logerr(f"Error processing request: {exc}\n{traceback.format_exception(exc_type, exc_value, tb)}")


class Service:
    """Serve ``service_class`` requests under ``name`` by calling ``handler(request)``.

    The handler returns the response (or a dict of its fields, a tuple/list of its fields, or a
    single field value). Returning None or raising sends an error to the client:
    ``ServiceException`` -> "service cannot process request: ...", anything else ->
    "error processing request: ..." (after ``error_handler(e, type, value, tb)`` ran).
    """

    def __init__(self, name: str, service_class: Any, handler: Callable[[Any], Any],
                 buff_size: int = DEFAULT_BUFF_SIZE,
                 error_handler: Callable[..., None] | None = None) -> None:
        if not name or not isinstance(name, str):
            raise ValueError("service name is not a non-empty string")
        if not names.is_legal_name(name):
            warnings.warn(f"'{name}' is not a legal ROS graph resource name. This may cause problems "
                          "with other ROS tools", stacklevel=2)
        self.name = name
        self.resolved_name = node.resolve_name(name)
        self.service_class = service_class
        self.request_class = service_class._request_class
        self.response_class = service_class._response_class
        self._read_request = reader_for(self.request_class)
        self.handler = handler
        self.error_handler = error_handler or _default_error_handler
        self.buff_size = buff_size
        self.seq = 0
        self._seqs = itertools.count(1)
        self.done = False
        node.register_service(self.resolved_name, self._handle_connection)

    @property
    def uri(self) -> str | None:
        """The ``rosrpc://host:port`` URI the master knows us by (None before init_node)."""
        try:
            host, port = node.get_tcpros_address()
        except ROSException:
            return None
        return f"{ROSRPC}{host}:{port}"

    # -- lifecycle ---------------------------------------------------------------------------

    def shutdown(self, reason: str = "") -> None:
        """Stop serving and unregister from the master."""
        if self.done:
            return
        self.done = True
        try:
            node.unregister_service(self.resolved_name)
        except Exception as exc:
            raise ServiceException(f"Unable to connect to master: {exc}") from None

    def spin(self) -> None:
        """Block until this service or the node shuts down."""
        while not self.done and not node.wait_for_shutdown(0.5):
            pass

    # -- the TCPROS exchange ---------------------------------------------------------------------

    def _header_fields(self) -> Dict[str, str]:
        return {"service": self.resolved_name, "type": self.service_class._type,
                "md5sum": self.service_class._md5sum, "callerid": node.get_caller_id()}

    def _handle_connection(self, sock: socket.socket, header: Dict[str, str],
                           conn: admission.Connection) -> None:
        """Serve one inbound connection (called in the node's connection thread)."""
        try:
            self._serve(sock, header, conn)
        except (TransportException, admission.Refused) as exc:
            _logger.debug("service [%s]: connection ended: %s", self.resolved_name, exc)
        finally:
            sockets.close(sock)

    def _serve(self, sock: socket.socket, header: Dict[str, str], conn: admission.Connection) -> None:
        """The exchange, under the TCPROS server's admission policy: a request must arrive by
        a deadline fixed from its length once it starts (a one-shot client must send it
        within the header timeout), its bytes count against the node's budget, and a
        persistent connection waiting for its next request may be closed to make room."""
        # A blocking socket: the wait for a request is one recv, as is the request itself; a
        # deadline sets a timeout while it applies (FrameSource), a send waits only when the
        # client reads nothing (_send_all), and node shutdown or an eviction wakes a thread
        # blocked here by shutting the socket down (the TCPROS server's close() and evict()).
        sock.settimeout(None)
        refuse = None
        if self.done:
            refuse = f"[{node.get_caller_id()}] is not a provider of  [{self.resolved_name}]"
        handshake = Handshake(Role.SERVICE_SERVER, self._header_fields(), refuse=refuse)
        _send_all(sock, handshake.opening_received(header))
        if handshake.state is State.REJECTED:
            logwarn(f"Could not process inbound connection: {handshake.error}{header}")
            return
        if handshake.state is State.CLOSED:  # a probe: wait_for_service checking we are alive
            return
        persistent = handshake.persistent
        reader = tcpros.FrameReader(buff_size=max(self.buff_size, 16), first_chunk=_FIRST_CHUNK)
        source = sockets.FrameSource(sock, reader, stop=node.is_shutdown, guard=conn)
        read_request = self._read_request
        conn.release(idle=True)
        while not self.done:
            wait_until = None if persistent else time.monotonic() + conn.limits.head_timeout
            frame = source.next(wait_until)  # charged, and busy once whole
            if frame is None:
                if not persistent:
                    logerr(f"incoming connection failed: {_PEER_GONE}")
                return
            try:
                request = read_request(frame)
            except Exception as exc:
                logerr(f"[{self.resolved_name}] error deserializing incoming request: {exc}")
                return
            request._connection_header = header
            if frame.__class__ is not bytes:
                # a big request in a buffer of its own: its memory is free once it is read
                # (a small one sits in the connection's receive buffer, held anyway)
                del frame
                conn.release()
            else:
                del frame
            try:
                _send_all(sock, self._respond(request))
            except TransportTerminated as exc:
                if not node.is_shutdown():
                    # the client left (or stalled) mid-response: one line, then the next one
                    # (rospy sends the error through the error handler and logs twice)
                    logerr(f"incoming connection failed: [{self.resolved_name}] response to "
                           f"[{header.get('callerid', '')}] not delivered: {exc}")
                return
            if not persistent:
                return
            del request
            conn.release(idle=True)

    def _respond(self, request: Any) -> Any:
        """What answers ``request`` (bytes or buffers for ``_send_all``): ok + response, or
        not-ok + error text."""
        try:
            response = self.handler(request)
            if response.__class__ is not self.response_class:
                response = _convert_return_to_response(response, self.response_class)
            seq = next(self._seqs)  # atomic: connections are served in threads of their own
            self.seq = seq
            stamp_header(response, seq)
            frame = _small_frame(response, _OK_PREFIX)
            if frame is not None:
                return frame
            buff = _Buffer()
            response.serialize(buff)
            # ok byte + length, then the response as written (not copied into one buffer)
            return buff.frame(_OK + tcpros.frame_prefix(buff.size))
        except ServiceException as exc:
            return tcpros.encode_service_error(f"service cannot process request: {exc}")
        except Exception as exc:
            exc_type, exc_value, tb = sys.exc_info()
            try:
                self.error_handler(exc, exc_type, exc_value, tb)
            except Exception:  # a broken error handler must not kill the connection
                _logger.exception("service [%s]: error handler failed", self.resolved_name)
            return tcpros.encode_service_error(f"error processing request: {exc}")


def _small_frame(msg: Any, prefix: Callable[..., bytes]) -> Any:
    """The frame of a message without array fields (strings and numbers: the usual request
    and response), serialized through its generated code in one piece: ``bytes``, or for a
    big one its prefix and body. None for any other message, and on a bad field value (the
    general path, ``serialize()``, names the field)."""
    if getattr(msg, "_zero_copy", True):
        return None
    parts: list = []
    try:
        msg._serialize_parts(parts.append)
    except Exception:  # noqa: BLE001 - serialize() raises it again, with the field's name
        return None
    body = b"".join(parts)
    size = len(body)
    head = prefix(1, size) if prefix is _OK_PREFIX else prefix(size)
    if size <= _JOIN_LIMIT:
        return head + body
    return [head, body]


class _Buffer:
    """Write-only sink for ``Message.serialize`` that keeps what is written without joining it.

    Big pieces (array and string fields) are kept as they are, without a copy; runs of small
    ones are joined as they come, so a message of many small fields does not hold thousands
    of objects. The frame is sent right after serialization, in the same thread, so pieces of
    mutable buffers need no snapshot.
    """

    __slots__ = ("_parts", "_small", "_small_size", "size")

    def __init__(self) -> None:
        self._parts: list = []
        self._small: list = []
        self._small_size = 0
        self.size = 0

    def write(self, data: Any) -> None:
        if data.__class__ is not bytes:
            view = memoryview(data)
            if view.format != "B" or view.ndim != 1:
                # byte-wise, so that a partial send can slice it (cast needs C order)
                view = view.cast("B") if view.c_contiguous else memoryview(view.tobytes())
            data = view
        size = len(data)
        self.size += size
        if size < _SMALL_PART:
            self._small.append(data)
            self._small_size += size
            if self._small_size >= _JOIN_LIMIT:
                self._flush()
            return
        self._flush()
        self._parts.append(data)

    def _flush(self) -> None:
        if self._small:
            self._parts.append(b"".join(self._small))
            self._small = []
            self._small_size = 0

    def frame(self, prefix: bytes) -> list:
        """``prefix`` + everything written, as a list of buffers for ``_send_all``."""
        self._flush()
        parts = self._parts
        if self.size <= _JOIN_LIMIT:
            return [b"".join([prefix, *parts])]  # one small send
        if parts[0].__class__ is bytes and len(parts[0]) < _SMALL_PART:
            parts[0] = prefix + parts[0]
        else:
            parts.insert(0, prefix)
        return parts


# --------------------------------------------------------------------------- client

#: argument types that are a request's field value, never a message
_PLAIN = frozenset((bool, int, float, str, bytes, list, tuple))


def _args_kwds_to_request(request_class: Any, args: tuple, kwds: dict) -> Any:
    """A request from call arguments: one request instance, positional fields or keywords."""
    if args and kwds:
        raise TypeError("publish() can be called with arguments or keywords, but not both.")
    if kwds:
        return request_class(**kwds)
    if len(args) == 1:
        arg = args[0]
        if arg.__class__ is request_class or arg.__class__ in _PLAIN:
            return arg if arg.__class__ is request_class else request_class(arg)
        if getattr(arg, "_md5sum", None) == request_class._md5sum:
            return arg
        if hasattr(arg, "_type") and hasattr(arg, "_slot_types"):  # some other message
            slot_types = request_class._slot_types
            if not slot_types:
                raise TypeError(f"expected [] but got [{arg._type}]")
            if arg._type != slot_types[0]:
                raise TypeError(f"expected [{slot_types[0]}] but got [{arg._type}]")
    return request_class(*args)


#: the proxies with a connection open, whose sockets node shutdown closes
_open_proxies: weakref.WeakSet[ServiceProxy] = weakref.WeakSet()
_proxies_lock = threading.Lock()
_hooked = False


def _watch_proxy(proxy: ServiceProxy) -> None:
    """``proxy`` has a connection open: node shutdown shuts its socket down, waking a call
    blocked on it (the call then raises ROSInterruptException)."""
    global _hooked
    with _proxies_lock:
        _open_proxies.add(proxy)
        if not _hooked:
            node.add_shutdown_hook(_close_proxies)
            _hooked = True


def _close_proxies(reason: str = "") -> None:
    with _proxies_lock:
        proxies = list(_open_proxies)
    for proxy in proxies:
        sock = proxy._sock
        if sock is not None:
            try:
                sock.shutdown(socket.SHUT_RDWR)
            except OSError:
                pass


def _lookup_service(resolved_name: str) -> str:
    """The ``rosrpc://`` URI of a service from the master (rospy's error texts)."""
    try:
        uri = node.master().lookup_service(resolved_name)
    except OSError:
        raise ServiceException("unable to contact master") from None
    except RemoteError as exc:
        _logger.error("[%s]: lookup service failed with message [%s]", resolved_name, exc)
        raise ServiceException(f"service [{resolved_name}] unavailable") from None
    try:
        parse_rosrpc_uri(uri)
    except ParameterInvalid:
        raise ServiceException(f"master returned invalid ROSRPC URI: {uri}") from None
    return uri


class ServiceProxy:
    """A callable handle on a remote service: ``proxy(1, 2)``, ``proxy(req)``, ``proxy(a=1, b=2)``."""

    def __init__(self, name: str, service_class: Any, persistent: bool = False,
                 headers: Dict[str, str] | None = None) -> None:
        self.name = name
        self.resolved_name = node.resolve_name(name)
        self.service_class = service_class
        self.request_class = service_class._request_class
        self.response_class = service_class._response_class
        self._read_response = reader_for(self.response_class)
        self.persistent = persistent
        self.headers: Dict[str, str] = dict(headers or {})
        if persistent:
            self.headers["persistent"] = "1"
        self.uri: str | None = None
        self.seq = 0
        self.buff_size = DEFAULT_BUFF_SIZE
        self._sock: socket.socket | None = None
        self._source: sockets.FrameSource | None = None
        self._server_header: Dict[str, str] = {}
        self._lock = threading.Lock()  # one call at a time on a persistent connection

    def wait_for_service(self, timeout: float | None = None) -> None:
        wait_for_service(self.resolved_name, timeout=timeout)

    def __call__(self, *args: Any, **kwds: Any) -> Any:
        return self.call(*args, **kwds)

    def _header_fields(self) -> Dict[str, str]:
        fields = {"service": self.resolved_name, "md5sum": self.service_class._md5sum,
                  "callerid": node.get_caller_id()}
        fields.update({str(k): str(v) for k, v in self.headers.items()})  # user headers win, as in rospy
        return fields

    def _open(self) -> None:
        """Look the service up, connect and exchange headers; ServiceException on failure."""
        uri = _lookup_service(self.resolved_name)
        self.uri = uri
        host, port = parse_rosrpc_uri(uri)
        try:
            sock = connect(host, port, CONNECT_TIMEOUT, nodelay=True)
        except OSError as exc:
            raise ServiceException(f"unable to connect to service: {exc}") from None
        try:
            header = negotiate(sock, Handshake(Role.SERVICE_CLIENT, self._header_fields()),
                               send=_send_all)
        except (TransportException, OSError) as exc:
            sockets.close(sock)
            raise ServiceException(f"unable to connect to service: {exc}") from None
        # blocking: a call is one send and one recv; node shutdown wakes a call waiting
        # for its response by shutting the socket down (_close_proxies)
        sock.settimeout(None)
        self._sock = sock
        _watch_proxy(self)
        self._server_header = header
        self._source = sockets.FrameSource(sock, tcpros.FrameReader(buff_size=self.buff_size, ok_byte=True),
                                           stop=node.is_shutdown)

    def _drop(self) -> None:
        sock, self._sock = self._sock, None
        self._source = None
        sockets.close(sock)

    def call(self, *args: Any, **kwds: Any) -> Any:
        """Call the service; returns the response message.

        Raises TypeError for a request of the wrong type, ServiceException when the service
        is unavailable or its handler failed, ROSInterruptException when the node shuts down
        during the call.
        """
        request = _args_kwds_to_request(self.request_class, args, kwds)
        if getattr(request, "_type", None) != self.request_class._type:
            raise TypeError(f"request object type [{request.__class__}] does not match service type [{self.request_class}]")
        with self._lock:
            if self._sock is None:
                self._open()
            try:
                # as rospy: a request is numbered once connected, and sent in that order
                self.seq += 1
                stamp_header(request, self.seq)
                frame = _small_frame(request, _REQUEST_PREFIX)
                if frame is None:
                    buff = _Buffer()
                    request.serialize(buff)
                    frame = buff.frame(tcpros.frame_prefix(buff.size))
                assert self._sock is not None and self._source is not None
                _send_all(self._sock, frame)
                del frame  # its joined small fields need not live while the response comes in
                reply = self._source.next()
                if reply is None:
                    raise TransportTerminated(_PEER_GONE)
            except TransportException as exc:
                self._drop()
                if isinstance(exc, tcpros.FrameError) and "closed" in str(exc):
                    exc = TransportTerminated(_PEER_GONE)  # rospy's words for a peer gone mid-reply
                if node.is_shutdown():
                    raise ROSInterruptException("node shutdown interrupted service call") from None
                raise ServiceException(f"transport error completing service call: {exc}") from None
            except BaseException:
                self._drop()
                raise
            header = self._server_header
            if not self.persistent:
                self._drop()
        ok, data = reply
        if not ok:
            # rospy (Python 3) formats the raw bytes of the error string, so its text reads
            # "... responded with an error: b'...'"; the same words here keep tools identical
            text = str(bytes(data))
            raise ServiceException(f"service [{self.resolved_name}] responded with an error: {text}")
        try:
            response = self._read_response(data)
        except Exception as exc:
            raise ServiceException(f"transport error completing service call: receive_once[{self.resolved_name}]: "
                                   f"DeserializationError {exc}") from None
        response._connection_header = header
        return response

    def close(self) -> None:
        """Close a persistent connection (no effect otherwise)."""
        with self._lock:
            self._drop()


def _probe_service(resolved_name: str, timeout: float) -> str | None:
    """Is the service registered and accepting connections? Sends a probe header and closes."""
    try:
        uri = node.master().lookup_service(resolved_name)
    except MasterError:  # not registered (yet)
        return None
    except RemoteError as exc:  # OSError (master down) goes to the caller
        raise TransportInitError(f"master lookup failed: {exc}") from None
    host, port = parse_rosrpc_uri(uri)
    sock = connect(host, port, timeout, nodelay=True)
    try:
        negotiate(sock, Handshake(Role.SERVICE_CLIENT, {
            "probe": "1", "md5sum": "*", "callerid": node.get_caller_id(),
            "service": resolved_name}), send=_send_all)
    finally:
        sockets.close(sock)
    return uri


def wait_for_service(service: str, timeout: float | None = None) -> None:
    """Block until ``service`` is registered and accepts connections.

    ``timeout`` (seconds or Duration) None waits forever; 0 is invalid (ValueError). Raises
    ROSException("timeout exceeded while waiting for service ...") on timeout and
    ROSInterruptException when the node shuts down meanwhile.
    """
    if timeout is not None and hasattr(timeout, "to_sec"):
        timeout = timeout.to_sec()
    if timeout == 0.0:
        raise ValueError("timeout must be non-zero")
    resolved_name = node.resolve_name(service)
    deadline = None if not timeout else time.monotonic() + timeout
    contact_failed = False
    while not node.is_shutdown():
        remaining = None if deadline is None else deadline - time.monotonic()
        if remaining is not None and remaining <= 0:
            break
        try:
            probe_timeout = 10.0 if remaining is None else max(0.01, remaining)
            uri = _probe_service(resolved_name, probe_timeout)
            if uri:
                if contact_failed:
                    loginfo(f"wait_for_service({resolved_name}): finally were able to contact [{uri}]")
                return
        except (OSError, ParameterInvalid, TransportException):
            contact_failed = True
            logwarn_throttle(10, f"wait_for_service({resolved_name}): failed to contact, will keep trying")
        pause = WAIT_FOR_SERVICE_INTERVAL
        if deadline is not None:
            pause = min(pause, max(0.0, deadline - time.monotonic()))
        if node.wait_for_shutdown(pause):
            break
    if node.is_shutdown():
        raise ROSInterruptException("rospy shutdown")
    raise ROSException(f"timeout exceeded while waiting for service {resolved_name}")
