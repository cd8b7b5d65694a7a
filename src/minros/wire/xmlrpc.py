"""XML-RPC for the master and slave APIs: a threaded HTTP/1.1 server and a client with timeouts;
HTTP for the XML-RPC bodies and nothing ROS-specific (the ``[code, statusMessage, value]``
convention is :mod:`minros.wire.rosapi`, the ROS_IP/ROS_HOSTNAME rules :mod:`minros.rosenv`).

Server behaviour matches what ROS nodes expect from rosgraph's ``ThreadingXMLRPCServer``:
HTTP/1.1 keep-alive, one thread per connection (so one kept-alive client never blocks another),
``system.multicall``, ``allow_none`` off, faults formatted as ``"<class 'E'>:message"`` with code 1.
On top of that it defends itself: requests are read by a sans-IO :class:`RequestReader`
under the deadlines, memory budget, connection cap and allow-list of
:class:`minros.wire.admission.Admission` (a trickling client cannot extend its deadline, bytes
are charged as they arrive, never as announced, a full server closes its idlest or slowest
connection); bodies over ``max_body`` are refused from their Content-Length, ``<!DOCTYPE``/
entities are refused (no entity expansion). Nothing is logged per request (and no reverse DNS
lookups are ever made).
"""

from __future__ import annotations

import logging
import re
import socket
import threading
import time
import xmlrpc.client
from typing import Any, Callable, Dict, List, Sequence, Tuple
from urllib.parse import urlparse
from xmlrpc.client import Binary, DateTime, Fault, ProtocolError  # noqa: F401 - re-exported

from minros.wire import admission
from minros.wire import trace as _trace

# ------------------------------------------------------------------ limits

DEFAULT_MAX_BODY = 64 * 1024 * 1024
DEFAULT_IDLE_TIMEOUT = 60.0
DEFAULT_MAX_CONNECTIONS = 1024
DEFAULT_CLIENT_TIMEOUT = 5.0
MAX_HEADER_LINE = 8192
MAX_HEADER_LINES = 100
#: arrays and structs nested deeper than this in a reply are refused: no ROS value is that
#: deep (Python's own XML-RPC writer stops near 450 levels, PyYAML's near 330), and consumers
#: walk values recursively, so a deeper reply would only end in a RecursionError
MAX_REPLY_DEPTH = 200


def _check_markup(body: bytes | bytearray) -> None:
    """Refuse DTDs: XML-RPC never needs them and they are the door to entity-expansion bombs."""
    if b"<!" in body:
        upper = body.upper()
        if b"<!DOCTYPE" in upper or b"<!ENTITY" in upper:
            raise ValueError("XML document type declarations and entities are not allowed")


def _fault_string(exc: BaseException) -> str:
    # The same text Python's SimpleXMLRPCServer (and therefore rosmaster/rospy) sends.
    return f"{type(exc)}:{exc}"


# ------------------------------------------------------------------ dispatch (sans-IO)


class Dispatcher:
    """Maps XML-RPC method names to the public methods of ``handler``.

    If ``handler`` defines ``_dispatch(method, params)`` it is used instead (as with
    ``SimpleXMLRPCServer.register_instance``). ``system.multicall`` and ``system.listMethods``
    are built in.
    """

    def __init__(self, handler: Any) -> None:
        self.handler = handler
        self._custom = getattr(handler, "_dispatch", None)
        self._cache: Dict[str, Callable[..., Any]] = {}

    def list_methods(self) -> List[str]:
        names = ["system.listMethods", "system.multicall"]
        for name in dir(self.handler):
            if not name.startswith("_") and callable(getattr(self.handler, name, None)):
                names.append(name)
        return sorted(names)

    def _lookup(self, method: Any) -> Callable[..., Any] | None:
        func: Callable[..., Any] | None = self._cache.get(method)
        if func is not None:
            return func
        if not isinstance(method, str) or not method or method.startswith("_") or "." in method:
            return None
        func = getattr(self.handler, method, None)
        if func is None or not callable(func):
            return None
        self._cache[method] = func
        return func  # type: ignore[no-any-return]  # what getattr found, checked callable

    def dispatch(self, method: Any, params: Sequence[Any]) -> Any:
        """Call ``method``; exceptions propagate (the caller turns them into faults)."""
        if method == "system.multicall":
            return self._multicall(*params)
        if method == "system.listMethods":
            return self.list_methods()
        if self._custom is not None:
            return self._custom(method, params)
        func = self._lookup(method)
        if func is None:
            raise Exception(f'method "{method}" is not supported')
        return func(*params)

    def _multicall(self, call_list: List[Dict[str, Any]]) -> List[Any]:
        results: List[Any] = []
        for call in call_list:
            method_name = call["methodName"]
            params = call["params"]
            try:
                results.append([self.dispatch(method_name, params)])
            except Fault as fault:
                results.append({"faultCode": fault.faultCode, "faultString": fault.faultString})
            except BaseException as exc:  # noqa: BLE001 - every failure becomes a fault entry
                results.append({"faultCode": 1, "faultString": _fault_string(exc)})
        return results

    def handle_request_body(self, body: bytes | bytearray) -> bytes:
        """Decode a methodCall, dispatch it, encode the methodResponse (or fault)."""
        try:
            _check_markup(body)
            params, method = xmlrpc.client.loads(body, use_builtin_types=False)
            response = xmlrpc.client.dumps((self.dispatch(method, params),), methodresponse=True,
                                           allow_none=False, encoding="utf-8")
        except Fault as fault:
            response = xmlrpc.client.dumps(fault, allow_none=False, encoding="utf-8")
        except BaseException as exc:  # noqa: BLE001 - the client gets a fault, the server lives on
            if isinstance(exc, (KeyboardInterrupt, SystemExit)):
                raise
            response = xmlrpc.client.dumps(Fault(1, _fault_string(exc)), allow_none=False,
                                           encoding="utf-8")
        return response.encode("utf-8", "xmlcharrefreplace")


# ------------------------------------------------------------------ HTTP requests (sans-IO)

_REASONS = {200: "OK", 400: "Bad Request", 403: "Forbidden", 404: "Not Found",
            408: "Request Timeout", 411: "Length Required", 413: "Payload Too Large",
            414: "URI Too Long", 431: "Request Header Fields Too Large", 501: "Not Implemented",
            503: "Service Unavailable", 505: "HTTP Version Not Supported"}
_RPC_PATHS = ("/", "/RPC2")
#: the longest request head: the request line and every header line at their limits
MAX_HEAD = MAX_HEADER_LINE * (MAX_HEADER_LINES + 1)


class _HttpError(Exception):
    def __init__(self, status: int, detail: str = "") -> None:
        super().__init__(detail or _REASONS.get(status, ""))
        self.status = status


def _status_response(status: int, detail: str) -> bytes:
    body = f"{status} {_REASONS.get(status, 'Error')}: {detail}\n".encode("utf-8", "replace")
    head = (f"HTTP/1.1 {status} {_REASONS.get(status, 'Error')}\r\nServer: minros\r\n"
            f"Content-Type: text/plain\r\nContent-Length: {len(body)}\r\nConnection: close\r\n\r\n")
    return head.encode("latin-1") + body


class RequestHead:
    """What the head of one XML-RPC request says."""

    __slots__ = ("version", "length", "keep_alive", "expect_continue", "raw")

    def __init__(self, version: str, length: int, keep_alive: bool, expect_continue: bool) -> None:
        self.version = version
        self.length = length
        self.keep_alive = keep_alive
        self.expect_continue = expect_continue
        self.raw = b""  # the head as received, blank line included (for the trace)


def parse_request_head(block: bytes, max_body: int) -> RequestHead:
    """Check the head of a request (request line and headers, without the blank line that
    ends it) and return what the server needs of it; _HttpError with the status otherwise."""
    lines = block.decode("latin-1").split("\n")  # latin-1: one character per byte
    line = lines[0].rstrip("\r")
    if len(line) > MAX_HEADER_LINE:
        raise _HttpError(414, "request line too long")
    parts = line.split()
    if len(parts) != 3:
        raise _HttpError(400, f"bad request line {line[:80]!r}")
    verb, path, version = parts
    if not version.startswith("HTTP/1."):
        raise _HttpError(505, version)
    if len(lines) - 1 > MAX_HEADER_LINES:
        raise _HttpError(431, "too many header lines")
    headers: Dict[str, str] = {}
    for hline in lines[1:]:
        if len(hline) > MAX_HEADER_LINE:
            raise _HttpError(431, "header line too long")
        key, sep, value = hline.partition(":")
        if not sep:
            raise _HttpError(400, "malformed header line")
        headers[key.strip().lower()] = value.strip()
    if verb != "POST":
        raise _HttpError(501, f"Unsupported method ({verb!r})")
    if path != "/" and path != "/RPC2" and path.split("?", 1)[0] not in _RPC_PATHS:
        raise _HttpError(404, path)
    if "transfer-encoding" in headers and "chunked" in headers["transfer-encoding"].lower():
        raise _HttpError(411, "chunked requests are not supported; send Content-Length")
    length_text = headers.get("content-length")
    if length_text is None:
        raise _HttpError(411, "Content-Length required")
    try:
        length = int(length_text)
    except ValueError:
        raise _HttpError(400, "bad Content-Length") from None
    if length < 0:
        raise _HttpError(400, "bad Content-Length")
    if length > max_body:
        raise _HttpError(413, f"body of {length} bytes exceeds the limit of {max_body}")
    connection = headers.get("connection", "").lower()
    if version == "HTTP/1.0":
        keep_alive = "keep-alive" in connection
    else:
        keep_alive = "close" not in connection
    expect = "expect" in headers and headers["expect"].lower() == "100-continue" and version != "HTTP/1.0"
    return RequestHead(version, length, keep_alive, expect)


class RequestReader:
    """XML-RPC requests out of a byte stream, without I/O (the way h11 reads HTTP).

    ``received(data)`` appends bytes; ``started()`` says whether a request has begun to
    arrive (blank lines between requests do not count); ``head()`` returns the parsed head
    once it is complete (None before; _HttpError when it is malformed or too long), and
    ``body()`` the body once it is complete. ``next_request()`` then starts over with the
    bytes that followed. Bytes are kept as they arrive: nothing is allocated for what a
    request only announces.
    """

    def __init__(self, max_body: int = DEFAULT_MAX_BODY) -> None:
        self.max_body = max_body
        self._buf = bytearray()
        self._scanned = 0  # bytes of _buf searched for the end of the head already
        self._head: RequestHead | None = None
        self._body = bytearray()

    def received(self, data: bytes) -> None:
        if self._head is None:
            self._buf += data
        else:
            self._body += data

    def started(self) -> bool:
        buf = self._buf
        if self._head is not None:
            return True
        if bytes(buf[:1]) in (b"\r", b"\n"):
            del buf[:len(buf) - len(buf.lstrip(b"\r\n"))]
            self._scanned = 0
        return bool(buf)

    def head(self) -> RequestHead | None:
        if self._head is not None:
            return self._head
        buf = self._buf
        if not self.started():
            return None
        # a head trickled in byte by byte is searched once, not once per byte
        since = max(0, self._scanned - 2)
        end = buf.find(b"\n\r\n", since)
        stop = end + 3
        bare = buf.find(b"\n\n", since)
        if bare >= 0 and (end < 0 or bare < end):
            end, stop = bare, bare + 2
        if end < 0:
            self._scanned = len(buf)
            if len(buf) > MAX_HEADER_LINE and buf.find(b"\n", 0, MAX_HEADER_LINE + 1) < 0:
                raise _HttpError(414, "request line too long")
            if len(buf) > MAX_HEAD:
                raise _HttpError(431, "request head too long")
            return None
        self._head = parse_request_head(bytes(buf[:end]), self.max_body)
        self._head.raw = bytes(buf[:stop])
        self._body = buf[stop:]
        self._buf = bytearray()
        self._scanned = 0
        return self._head

    def body(self) -> bytearray | None:
        head = self.head()
        if head is None or len(self._body) < head.length:
            return None
        body = self._body
        if len(body) > head.length:  # the start of a pipelined next request
            self._buf = body[head.length:]
            del body[head.length:]
        return body

    def next_request(self) -> int:
        """Forget the request just served; returns the bytes already held of the next one."""
        self._head = None
        self._body = bytearray()
        return len(self._buf)


# ------------------------------------------------------------------ HTTP server

_logger = logging.getLogger("minros.xmlrpc")
#: per connection thread: the hooks of the request being handled (None outside a request)
_request = threading.local()
_RECV_SIZE = 65536


def after_reply(hook: Callable[[], Any]) -> None:
    """Run ``hook()`` once the reply to the request being handled has been sent, in the same
    thread. An API method that ends the server (``shutdown``) uses it, so that its own reply
    still reaches the caller without a grace sleep. Outside a request, ``hook`` runs now."""
    hooks = getattr(_request, "after_reply", None)
    if hooks is None:
        hook()
    else:
        hooks.append(hook)


def _report_refusal(peer: str, reason: str) -> None:
    _logger.warning("%s", reason)


class _Closed(Exception):
    """The connection ends quietly: peer gone, idle too long, or closed to make room."""


class XmlRpcServer:
    """Threaded XML-RPC server for ``handler`` (see module docstring).

    ``start()`` binds, listens and returns; ``port`` is then the bound port. ``shutdown()`` closes
    the listening socket and every open connection. Who is served, for how long and with how
    much memory is :class:`minros.wire.admission.Admission`'s policy (``limits``); ``allowed``
    is the allow-list (:func:`minros.rosenv.allowed_hosts`), and ``on_refused(peer, reason)``
    reports a refused peer (rate-limited by the policy).
    """

    def __init__(self, handler: Any, host: str = "", port: int = 0, *,
                 max_body: int = DEFAULT_MAX_BODY, idle_timeout: float = DEFAULT_IDLE_TIMEOUT,
                 max_connections: int = DEFAULT_MAX_CONNECTIONS, backlog: int = 1024,
                 ipv6: bool | None = None, body_budget: int | None = None,
                 limits: admission.Limits | None = None,
                 allowed: Sequence[Any] | None = None,
                 on_refused: Callable[[str, str], Any] = _report_refusal,
                 what: str = "") -> None:
        self.dispatcher = Dispatcher(handler)
        self.host = host
        self.requested_port = port
        self.max_body = max_body
        if limits is None:
            budget = max(max_body, body_budget if body_budget is not None else 4 * max_body)
            limits = admission.Limits(max_connections=max_connections, idle_timeout=idle_timeout,
                                      budget=budget)
        self.limits = limits
        self.admission = admission.Admission(limits, allowed, what=what or "this XML-RPC server")
        self.on_refused = on_refused
        self.backlog = backlog
        self.ipv6 = (":" in host) if ipv6 is None else ipv6
        self._sock: socket.socket | None = None
        # the hard bound on connection threads; evicted ones release it as they exit
        self._slots = threading.BoundedSemaphore(limits.max_connections)
        self._conns: Dict[int, socket.socket] = {}
        self._conn_threads: Dict[int, threading.Thread] = {}
        self._conns_lock = threading.Lock()
        self._stopping = threading.Event()
        self._thread: threading.Thread | None = None
        self.port = 0

    # -- life cycle

    def start(self) -> XmlRpcServer:
        family = socket.AF_INET6 if self.ipv6 else socket.AF_INET
        sock = socket.socket(family, socket.SOCK_STREAM)
        try:
            sock.setsockopt(socket.SOL_SOCKET, socket.SO_REUSEADDR, 1)
            bind_host = self.host or ("::" if self.ipv6 else "0.0.0.0")
            sock.bind((bind_host, self.requested_port))
            sock.listen(self.backlog)
        except BaseException:
            sock.close()
            raise
        self._sock = sock
        self.port = sock.getsockname()[1]
        self._thread = threading.Thread(target=self._accept_loop, name=f"xmlrpc-accept:{self.port}",
                                        daemon=True)
        self._thread.start()
        return self

    def shutdown(self) -> None:
        self._stopping.set()
        sock, self._sock = self._sock, None
        if sock is not None:
            try:
                sock.shutdown(socket.SHUT_RDWR)  # wakes the blocked accept() on Linux
            except OSError:
                pass
            sock.close()
        with self._conns_lock:
            conns = list(self._conns.values())
            threads = list(self._conn_threads.values())
        for conn in conns:
            _shut(conn)
        # joined, so that what a connection does after its last reply (an after-reply hook,
        # its trace event) is done when shutdown returns; bounded, and never this thread
        # (shutdown may run in a connection's after-reply hook)
        deadline = time.monotonic() + 2.0
        for thread in [self._thread, *threads]:
            if thread is not None and thread is not threading.current_thread():
                thread.join(max(0.0, deadline - time.monotonic()))

    def serve_forever(self) -> None:
        """Block until :meth:`shutdown` (the accept thread serves; this is for callers written
        for socketserver, whose server loop runs in the calling thread)."""
        self._stopping.wait()

    def connection_count(self) -> int:
        with self._conns_lock:
            return len(self._conns)

    def _evict(self, keys: List[int]) -> None:
        """Close connections the policy chose to make room (their threads then exit)."""
        for key in keys:
            with self._conns_lock:
                conn = self._conns.get(key)
            if conn is not None:
                _shut(conn)

    # -- accepting

    def _accept_loop(self) -> None:
        sock = self._sock
        assert sock is not None
        while not self._stopping.is_set():
            try:
                conn, addr = sock.accept()
            except OSError:
                if self._stopping.is_set():
                    return
                # e.g. EMFILE (out of file descriptors): back off instead of spinning
                self._stopping.wait(0.05)
                continue
            self._admit(conn, addr)

    def _admit(self, conn: socket.socket, addr: Any) -> None:
        """Serve ``conn`` in a thread of its own if the policy lets it in (closing others to
        make room when the server is full); refuse it with one status line otherwise."""
        key = self.admission.new_key()
        try:
            victims = self.admission.admit(key, addr[0], _local_address(conn),
                                           admission.ADMIT_GRACE)
        except admission.Refused as refused:
            if refused.report:
                self.on_refused(addr[0], str(refused))
            _refuse(conn, refused.status, str(refused))
            return
        except OSError:  # the peer left already
            self.admission.leave(key)
            conn.close()
            return
        self._evict(victims)
        # the evicted connections' threads exit at once; wait for one of their slots
        if not self._slots.acquire(timeout=2.0):
            self.admission.leave(key)
            _refuse(conn, 503, "server busy, try again")
            return
        try:
            conn.setsockopt(socket.IPPROTO_TCP, socket.TCP_NODELAY, 1)
            thread = threading.Thread(target=self._serve_connection, args=(conn, key),
                                      daemon=True, name=f"xmlrpc-conn:{self.port}")
            with self._conns_lock:
                self._conns[key] = conn
                self._conn_threads[key] = thread
            thread.start()
        except BaseException:  # noqa: BLE001 - e.g. cannot start a thread: drop this client
            with self._conns_lock:
                self._conns.pop(key, None)
                self._conn_threads.pop(key, None)
            self.admission.leave(key)
            conn.close()
            self._slots.release()

    # -- one connection, many requests (keep-alive)

    def _serve_connection(self, conn: socket.socket, key: int) -> None:
        reader = RequestReader(self.max_body)
        served = 0  # requests on this connection (the trace numbers them)
        addresses: Tuple[str, str] | None = None
        try:
            while not self._stopping.is_set():
                try:
                    head, body = self._read_request(conn, key, reader)
                except _HttpError as err:
                    _send_quietly(conn, _status_response(err.status, str(err)))
                    return
                except admission.Refused as refused:
                    _send_quietly(conn, _status_response(refused.status, str(refused)))
                    return
                except _Closed:
                    return
                self.admission.set_state(key, admission.BUSY)
                served += 1
                traced = _trace.ON
                t0 = time.time() if traced else 0.0
                if traced and addresses is None:
                    addresses = _addresses(conn)  # now: the peer may be gone after the reply
                hooks: List[Callable[[], Any]] = []
                _request.after_reply = hooks
                try:
                    payload = self.dispatcher.handle_request_body(body)
                finally:
                    _request.after_reply = None
                    if not traced:
                        del body  # not held while the reply goes out
                    self.admission.release(key)
                    leftover = reader.next_request()
                head_text = ("HTTP/1.1 200 OK\r\nServer: minros\r\nContent-type: text/xml\r\n"
                             f"Content-length: {len(payload)}\r\n"
                             + ("" if head.keep_alive else "Connection: close\r\n") + "\r\n")
                response = head_text.encode("latin-1") + payload
                try:
                    # a client that does not read its reply has until the deadline to start
                    conn.settimeout(self.limits.transfer_time(len(payload)))
                    conn.sendall(response)
                    self.admission.set_state(key, admission.IDLE)
                    if traced:
                        request = bytes(body)
                        del body
                        _trace.xmlrpc_served(addresses or ("?", "?"), served, t0,
                                             head.raw + request, request, response, payload)
                finally:
                    for hook in hooks:
                        try:
                            hook()
                        except Exception:  # noqa: BLE001 - a hook must not end the connection thread
                            _logger.exception("after-reply hook failed")
                if not head.keep_alive:
                    return
                if leftover:  # a pipelined request: its first bytes are in memory already
                    self._evict(self.admission.charge(key, leftover))
        except (OSError, ValueError, admission.Refused):
            pass  # peer went away, did not read its reply, or shutdown
        finally:
            try:
                conn.close()
            except OSError:
                pass
            with self._conns_lock:
                self._conns.pop(key, None)
                self._conn_threads.pop(key, None)
            self.admission.leave(key)
            self._slots.release()

    def _read_request(self, conn: socket.socket, key: int, reader: RequestReader
                      ) -> Tuple[RequestHead, bytearray]:
        """Read one request under the policy's deadlines and memory budget."""
        limits = self.limits
        idle_until = time.monotonic() + limits.idle_timeout
        while not reader.started():
            self._receive(conn, key, reader, idle_until, None)
        start = time.monotonic()  # the policy took the first bytes' charge as the start too
        deadline = start + limits.head_timeout
        while (head := reader.head()) is None:
            self._receive(conn, key, reader, deadline, "request head")
        if head.expect_continue:
            conn.settimeout(limits.head_timeout)
            conn.sendall(b"HTTP/1.1 100 Continue\r\n\r\n")  # curl & co. wait for it
        deadline = limits.body_deadline(start, head.length)
        while (body := reader.body()) is None:
            self._receive(conn, key, reader, deadline, "request body")
        return head, body

    def _receive(self, conn: socket.socket, key: int, reader: RequestReader, deadline: float,
                 what: str | None) -> None:
        """One recv before ``deadline``, charged to the budget as it arrives. ``what`` names
        the part of a request being read (None: waiting between requests, which ends quietly)."""
        remaining = deadline - time.monotonic()
        if remaining <= 0:
            if what is None:
                raise _Closed()
            raise _HttpError(408, f"{what} not received within the deadline")
        conn.settimeout(remaining)
        try:
            data = conn.recv(_RECV_SIZE)
        except socket.timeout:
            if what is None:
                raise _Closed() from None
            raise _HttpError(408, f"{what} not received within the deadline") from None
        if not data:  # the peer left, or the server closed the connection (shutdown, eviction)
            raise _Closed()
        victims = self.admission.charge(key, len(data))  # Refused once evicted
        if victims:
            self._evict(victims)
        reader.received(data)


def _addresses(sock: socket.socket) -> Tuple[str, str]:
    """(local, remote) ``host:port`` of a connected socket, for the trace."""
    try:
        return _trace.address(sock.getsockname()), _trace.address(sock.getpeername())
    except OSError:
        return "?", "?"


def _local_address(conn: socket.socket) -> str | None:
    """The address a connection arrived at (a peer at that address is this host)."""
    name = conn.getsockname()
    return name[0] if isinstance(name, tuple) else None


def _shut(conn: socket.socket) -> None:
    try:
        conn.shutdown(socket.SHUT_RDWR)
    except OSError:
        pass


def _send_quietly(conn: socket.socket, data: bytes) -> None:
    try:
        conn.settimeout(1.0)
        conn.sendall(data)
    except OSError:
        pass


def _refuse(conn: socket.socket, status: int, reason: str) -> None:
    """Answer a connection the server will not serve with one status line, then close it."""
    _send_quietly(conn, _status_response(status, reason))
    try:
        conn.close()
    except OSError:
        pass


# ------------------------------------------------------------------ client


class CallError(xmlrpc.client.Error):
    """A call failed for a reason the client recognised: ``str()`` is one line that names it
    (and the fix), which the tools print instead of a traceback."""

    def __init__(self, url: str, errcode: int, errmsg: str, headers: Dict[str, str],
                 text: str) -> None:
        xmlrpc.client.Error.__init__(self)  # not ProtocolError's: the fields are set here
        self.url = url
        self.errcode = errcode
        self.errmsg = errmsg
        self.headers = headers
        self.text = text

    def __str__(self) -> str:
        return self.text

    def __repr__(self) -> str:
        return f"<{type(self).__name__}: {self.text}>"


class CallRefused(CallError, ProtocolError):
    """The server answered with an HTTP error status (``errcode``) and ``errmsg`` saying why:
    minros's servers answer 413 to a request over their size limit and 403 to a peer outside
    their ROS_ALLOWED_HOSTS. An :class:`xmlrpc.client.ProtocolError`, as before."""


class BadReply(CallError, ProtocolError, xmlrpc.client.ResponseError):
    """The reply is not an XML-RPC response this client accepts: not HTTP, not XML-RPC, a DTD,
    nested deeper than :data:`MAX_REPLY_DEPTH`, or larger than the client's limit. Both a
    ProtocolError and a ResponseError, so code catching either of Python's keeps working."""


_LIMIT_OF = re.compile(r"limit of (\d+)")


def _refusal(uri: str, status: int, reason: str, headers: Dict[str, str],
             request_size: int) -> CallRefused:
    """The one-line explanation of an HTTP error status (``reason``: the server's own line)."""
    detail = reason.split(": ", 1)[1] if reason[:3] == str(status) and ": " in reason else reason
    if status == 413:
        found = _LIMIT_OF.search(reason)
        limit = f"its limit of {_size(int(found.group(1)))}" if found else "its size limit"
        text = (f"{uri} refused a request of {_size(request_size)}: larger than {limit} "
                "per XML-RPC call (keep large data out of parameters and service arguments: "
                "send it on a topic or as a file)")
    elif status == 403 and "ROS_ALLOWED_HOSTS" in reason:
        text = (f"{uri} refused this host: {detail} (add this host's address to "
                "ROS_ALLOWED_HOSTS where that server runs)")
    else:
        text = f"{uri} answered HTTP {status}: {detail or 'no reason given'}"
    return CallRefused(uri, status, reason, headers, text)


def _size(n: int) -> str:
    mib = n / (1024 * 1024)
    return f"{n} bytes ({mib:.0f} MiB)" if n >= 1024 * 1024 else f"{n} bytes"


_NESTING = re.compile(rb"<(/?)(?:[A-Za-z_][\w.-]*:)?(?:array|struct)\s*>")


def check_nesting(data: bytes, limit: int = MAX_REPLY_DEPTH) -> None:
    """ValueError when arrays and structs in ``data`` nest deeper than ``limit``. Counting the
    opening tags first (in C) makes the usual reply cost one pass of ``bytes.count``."""
    if data.count(b"<array") + data.count(b"<struct") + data.count(b":array") \
            + data.count(b":struct") <= limit:
        return
    depth = 0
    for match in _NESTING.finditer(data):
        if match.group(1):
            depth -= 1
        else:
            depth += 1
            if depth > limit:
                raise ValueError(f"arrays and structs nested more than {limit} deep")


def parse_reply(data: bytes) -> Any:
    """The value of a methodResponse; Fault for a fault response, ValueError (or the XML
    parser's error) for anything else."""
    _check_markup(data)
    check_nesting(data)
    result, _ = xmlrpc.client.loads(data, use_builtin_types=False)
    return result[0] if len(result) == 1 else result


class _Method:
    __slots__ = ("_send", "_name")

    def __init__(self, send: Callable[[str, Tuple[Any, ...]], Any], name: str) -> None:
        self._send = send
        self._name = name

    def __getattr__(self, name: str) -> _Method:
        return _Method(self._send, f"{self._name}.{name}")

    def __call__(self, *args: Any) -> Any:
        return self._send(self._name, args)


class ServerProxy:
    """XML-RPC client with connect/read timeouts and a kept-alive connection.

    Thread-safe (calls on one proxy are serialized). ``proxy.method(*args)`` returns the raw
    result; faults raise :class:`xmlrpc.client.Fault`, network failures and timeouts
    :class:`OSError`; what the client recognises raises a :class:`CallError` whose one line
    says what happened: :class:`CallRefused` for an HTTP error status (the server's reason
    kept: a request over its size limit, a host outside its ROS_ALLOWED_HOSTS),
    :class:`BadReply` for a reply that is not XML-RPC (garbage, a DTD, nested too deep, too
    large). Both are :class:`ProtocolError` too.
    """

    def __init__(self, uri: str, timeout: float | None = DEFAULT_CLIENT_TIMEOUT, *,
                 max_body: int = DEFAULT_MAX_BODY) -> None:
        parsed = urlparse(uri)
        if parsed.scheme != "http" or not parsed.hostname:
            raise ValueError(f"not an http XML-RPC URI: {uri!r}")
        self.uri = uri
        self._address = (parsed.hostname, parsed.port or 80)
        path = parsed.path or "/RPC2"
        self._head = (f"POST {path} HTTP/1.1\r\nHost: {parsed.netloc}\r\nUser-Agent: minros\r\n"
                      "Content-Type: text/xml\r\nContent-Length: ")
        self.timeout = timeout
        self.max_body = max_body
        self._sock: socket.socket | None = None
        self._reader: Any = None
        self._lock = threading.Lock()
        # for the trace: requests sent on this socket, its addresses, the last raw response
        self._sent = 0
        self._addresses: Tuple[str, str] | None = None
        self._response: bytes | None = None

    def __getattr__(self, name: str) -> _Method:
        if name.startswith("__"):
            raise AttributeError(name)
        return _Method(self._request, name)

    def __repr__(self) -> str:
        return f"<minros ServerProxy {self.uri}>"

    def close(self) -> None:
        with self._lock:
            self._drop()

    def __enter__(self) -> ServerProxy:
        return self

    def __exit__(self, *exc: Any) -> None:
        self.close()

    def _request(self, method: str, params: Tuple[Any, ...]) -> Any:
        body = xmlrpc.client.dumps(params, method, allow_none=False, encoding="utf-8").encode(
            "utf-8", "xmlcharrefreplace")
        request = (self._head + f"{len(body)}\r\n\r\n").encode("latin-1") + body
        with self._lock:
            for attempt in (0, 1):
                reused = self._sock is not None
                t0 = time.time() if _trace.ON else 0.0
                try:
                    result = self._single_request(request, len(body))
                except (ConnectionResetError, ConnectionAbortedError, BrokenPipeError,
                        _PeerClosed) as exc:
                    if t0:
                        self._trace(method, params, request, t0, error=exc)
                    self._drop()
                    # A kept-alive connection the server closed while idle: retry once afresh.
                    if attempt or not reused:
                        raise
                except BaseException as exc:
                    if t0:
                        self._trace(method, params, request, t0, error=exc)
                    self._drop()
                    raise
                else:
                    if t0:
                        self._trace(method, params, request, t0, result=result)
                    return result
        raise AssertionError("unreachable")

    def _trace(self, method: str, params: Tuple[Any, ...], request: bytes, t0: float,
               result: Any = None, error: BaseException | None = None) -> None:
        response, self._response = self._response, None
        _trace.xmlrpc_called(self.uri, method, params, self._sent, self._addresses, t0, request,
                             response, result, error)

    def _drop(self) -> None:
        if self._reader is not None:
            try:
                self._reader.close()
            except OSError:
                pass
            self._reader = None
        if self._sock is not None:
            try:
                self._sock.close()
            except OSError:
                pass
            self._sock = None

    def _single_request(self, request: bytes, body_size: int) -> Any:
        if self._sock is None:
            self._addresses = None
            sock = socket.create_connection(self._address, timeout=self.timeout)
            sock.setsockopt(socket.IPPROTO_TCP, socket.TCP_NODELAY, 1)
            self._sock = sock
            self._reader = sock.makefile("rb", buffering=65536)
            self._sent = 0
            if _trace.ON:
                self._addresses = _addresses(sock)
        self._sent += 1
        try:
            self._sock.sendall(request)
        except (BrokenPipeError, ConnectionResetError) as exc:
            # A server that will not take a request (413 over its size limit, 403 outside its
            # allow-list) answers at once and closes without reading the rest, so the send
            # fails; its answer is in this socket's receive buffer already.
            refusal = self._refusal_after_send_failed(body_size)
            if refusal is not None:
                raise refusal from exc
            raise
        return self._read_reply(body_size)

    def _refusal_after_send_failed(self, body_size: int) -> CallRefused | None:
        try:
            assert self._sock is not None
            self._sock.settimeout(min(self.timeout or 1.0, 1.0))
            self._read_reply(body_size)
        except CallRefused as refusal:
            return refusal
        except (OSError, xmlrpc.client.Error, ValueError):
            pass
        return None

    def _bad(self, what: str, status: int = 0, headers: Dict[str, str] | None = None) -> BadReply:
        return BadReply(self.uri, status, what, headers or {}, f"{self.uri} sent a bad reply: {what}")

    def _read_reply(self, body_size: int) -> Any:
        reader = self._reader
        status_line = reader.readline(MAX_HEADER_LINE + 1)
        raw_head = [status_line]
        if not status_line:
            raise _PeerClosed("connection closed by the server")
        parts = status_line.decode("latin-1").split(None, 2)
        if len(parts) < 2 or not parts[0].startswith("HTTP/") or not parts[1].isdigit():
            raise self._bad(f"not HTTP: {status_line[:80]!r}")
        status = int(parts[1])
        reason = parts[2].strip() if len(parts) > 2 else ""
        headers: Dict[str, str] = {}
        for _ in range(MAX_HEADER_LINES + 1):
            line = reader.readline(MAX_HEADER_LINE + 1)
            raw_head.append(line)
            if line in (b"\r\n", b"\n", b""):
                break
            key, _sep, value = line.decode("latin-1").partition(":")
            headers[key.strip().lower()] = value.strip()
        else:
            raise self._bad(f"more than {MAX_HEADER_LINES} header lines", status, headers)
        length_text = headers.get("content-length")
        close = ("close" in headers.get("connection", "").lower()
                 or parts[0] == "HTTP/1.0" and "keep-alive" not in headers.get("connection", "").lower())
        too_large = f"larger than this client's limit of {_size(self.max_body)}"
        if length_text is None:
            data = reader.read(self.max_body + 1)  # body delimited by the end of the connection
            close = True
        else:
            try:
                length = int(length_text)
            except ValueError:
                raise self._bad(f"bad Content-Length {length_text[:40]!r}", status,
                                headers) from None
            if length < 0 or length > self.max_body:
                raise self._bad(f"a body of {length} bytes, {too_large}", status, headers)
            data = reader.read(length)
            if len(data) != length:
                raise _PeerClosed("connection closed mid-response")
        if _trace.ON:
            self._response = b"".join(raw_head) + data
        if close:
            self._drop()
        if len(data) > self.max_body:
            raise self._bad(f"a body {too_large}", status, headers)
        if status != 200:
            self._drop()
            if headers.get("content-type", "").startswith("text/plain") and len(data) < 1024:
                # a refusal's one line says why (minros's servers name the setting to change)
                reason = data.decode("utf-8", "replace").strip() or reason
            raise _refusal(self.uri, status, reason, headers, body_size)
        try:
            return parse_reply(data)
        except Fault:
            raise
        except Exception as exc:  # noqa: BLE001 - expat, ValueError, TypeError, ...: not XML-RPC
            what = _one_line(exc)
            raise BadReply(self.uri, status, what, headers,
                           f"{self.uri} sent a reply that is not XML-RPC ({what})") from None


def _one_line(exc: BaseException) -> str:
    if isinstance(exc, xmlrpc.client.ResponseError) and not exc.args:
        return "no methodResponse value in it"  # what the unmarshaller's bare error means
    text = " ".join(str(exc).split())
    return text[:200] if text else type(exc).__name__


class _PeerClosed(ConnectionError):
    """The server closed a kept-alive connection before answering."""
