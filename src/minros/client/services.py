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

Both ends are transports of the seam, as a topic's are (``minros.transport.tcpros_service``:
the stream, the header exchange, bounded sends, frames read under admission); requests and
responses are serialized as topic frames are (``client.msg.serialize_frame``). This module holds what
a service is: the handler's rules, the proxy's, and rospy's error texts.
"""

from __future__ import annotations

import itertools
import logging
import socket
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
from minros.client.msg import serialize_frame, stamp_header
from minros.exceptions import (
    ROSException,
    ROSInterruptException,
    ROSSerializationException,
    SerializationError,
    ServiceException,
    TransportException,
    TransportInitError,
    TransportTerminated,
)
from minros.msgs import reader_for
from minros.transport import tcpros_service
from minros.transport.tcpros_service import ServiceClientEnd, ServiceServerEnd, connect_service
from minros.wire import admission, tcpros
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
#: a send gives up on a peer that took no byte for this long (the transport's)
SEND_STALL_TIMEOUT = tcpros_service.SEND_STALL_TIMEOUT
#: a request's own buffer starts this small and doubles as its bytes arrive (a lying length
#: costs nothing: a server must not allocate what a client only announces)
_FIRST_CHUNK = 64 << 10
#: the ok byte that starts a successful service response
_OK = b"\x01"

_logger = logging.getLogger("rospy.service")


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
        end = ServiceServerEnd(sock, self.resolved_name, conn, max(self.buff_size, 16),
                               _FIRST_CHUNK, stop=node.is_shutdown)
        try:
            self._serve(end, header, conn)
        except (TransportException, admission.Refused) as exc:
            _logger.debug("service [%s]: connection ended: %s", self.resolved_name, exc)
        finally:
            end.close()

    def _serve(self, end: ServiceServerEnd, header: Dict[str, str],
               conn: admission.Connection) -> None:
        """The exchange, under the TCPROS server's admission policy: a request must arrive by
        a deadline fixed from its length once it starts (a one-shot client must send it
        within the header timeout), its bytes count against the node's budget, and a
        persistent connection waiting for its next request may be closed to make room."""
        refuse = None
        if self.done:
            refuse = f"[{node.get_caller_id()}] is not a provider of  [{self.resolved_name}]"
        handshake = Handshake(Role.SERVICE_SERVER, self._header_fields(), refuse=refuse)
        end.negotiate(handshake, header)
        if handshake.state is State.REJECTED:
            logwarn(f"Could not process inbound connection: {handshake.error}{header}")
            return
        if handshake.state is State.CLOSED:  # a probe: wait_for_service checking we are alive
            return
        persistent = end.persistent
        read_request = self._read_request
        conn.release(idle=True)
        while not self.done:
            wait_until = None if persistent else time.monotonic() + conn.limits.head_timeout
            frame = end.next_request(wait_until)  # charged, and busy once whole
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
                end.send_all(self._respond(request))
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
        """What answers ``request`` (bytes or buffers for the connection's send): ok + response, or
        not-ok + error text."""
        try:
            response = self.handler(request)
            if response.__class__ is not self.response_class:
                response = _convert_return_to_response(response, self.response_class)
            seq = next(self._seqs)  # atomic: connections are served in threads of their own
            self.seq = seq
            stamp_header(response, seq)
            # ok byte + length, then the response as serialized (big fields not copied)
            return serialize_frame(response, _OK, snapshot=False)
        except ServiceException as exc:
            return tcpros.encode_service_error(f"service cannot process request: {exc}")
        except Exception as exc:
            exc_type, exc_value, tb = sys.exc_info()
            try:
                self.error_handler(exc, exc_type, exc_value, tb)
            except Exception:  # a broken error handler must not kill the connection
                _logger.exception("service [%s]: error handler failed", self.resolved_name)
            return tcpros.encode_service_error(f"error processing request: {exc}")


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
        end = proxy._end
        if end is not None:
            try:
                end.stream.shutdown(socket.SHUT_RDWR)
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
        self._end: ServiceClientEnd | None = None
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

    def _open(self) -> ServiceClientEnd:
        """Look the service up, connect and exchange headers; ServiceException on failure."""
        uri = _lookup_service(self.resolved_name)
        self.uri = uri
        host, port = parse_rosrpc_uri(uri)
        try:
            end = connect_service(host, port, self.resolved_name, CONNECT_TIMEOUT,
                                  stop=node.is_shutdown, buff_size=self.buff_size)
        except OSError as exc:
            raise ServiceException(f"unable to connect to service: {exc}") from None
        try:
            end.negotiate(Handshake(Role.SERVICE_CLIENT, self._header_fields()))
        except (TransportException, OSError) as exc:
            end.close()
            raise ServiceException(f"unable to connect to service: {exc}") from None
        # blocking: a call is one send and one recv; node shutdown wakes a call waiting
        # for its response by shutting the socket down (_close_proxies)
        self._end = end
        _watch_proxy(self)
        return end

    def _drop(self) -> None:
        end, self._end = self._end, None
        if end is not None:
            end.close()

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
            end = self._end if self._end is not None else self._open()
            try:
                # as rospy: a request is numbered once connected, and sent in that order
                self.seq += 1
                stamp_header(request, self.seq)
                try:
                    frame = serialize_frame(request, snapshot=False)
                except ROSSerializationException as exc:  # genpy's, as rospy raises it
                    raise SerializationError(str(exc)) from None
                reply = end.call(frame)
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
            header = end.header
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
    end = connect_service(host, port, resolved_name, timeout, stop=node.is_shutdown)
    try:
        end.negotiate(Handshake(Role.SERVICE_CLIENT, {
            "probe": "1", "md5sum": "*", "callerid": node.get_caller_id(),
            "service": resolved_name}))
    finally:
        end.close()
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
