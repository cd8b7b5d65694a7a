"""XML-RPC for the master and slave APIs: a threaded HTTP/1.1 server and a client with timeouts;
HTTP for the XML-RPC bodies and nothing ROS-specific (the ``[code, statusMessage, value]``
convention is :mod:`minros.wire.rosapi`, the ROS_IP/ROS_HOSTNAME rules :mod:`minros.rosenv`).

Server behaviour matches what ROS nodes expect from rosgraph's ``ThreadingXMLRPCServer``:
HTTP/1.1 keep-alive, one thread per connection (so one kept-alive client never blocks another),
``system.multicall``, ``allow_none`` off, faults formatted as ``"<class 'E'>:message"`` with code 1.
On top of that it defends itself: bodies over ``max_body`` are refused from their Content-Length
before any byte is read, ``<!DOCTYPE``/entities are refused (no entity expansion), clients that
connect and stay silent are dropped after ``idle_timeout``, and the number of connection threads
is bounded. Nothing is logged per request (and no reverse DNS lookups are ever made).
"""

from __future__ import annotations

import logging
import socket
import threading
import time
import xmlrpc.client
from typing import Any, Callable, Dict, List, Sequence, Tuple
from urllib.parse import urlparse
from xmlrpc.client import Binary, DateTime, Fault, ProtocolError  # noqa: F401 - re-exported

# ------------------------------------------------------------------ limits

DEFAULT_MAX_BODY = 64 * 1024 * 1024
DEFAULT_IDLE_TIMEOUT = 60.0
DEFAULT_MAX_CONNECTIONS = 1024
DEFAULT_CLIENT_TIMEOUT = 5.0
MAX_HEADER_LINE = 8192
MAX_HEADER_LINES = 100


def _check_markup(body: bytes) -> None:
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
        func = self._cache.get(method)
        if func is not None:
            return func
        if not isinstance(method, str) or not method or method.startswith("_") or "." in method:
            return None
        func = getattr(self.handler, method, None)
        if func is None or not callable(func):
            return None
        self._cache[method] = func
        return func

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

    def handle_request_body(self, body: bytes) -> bytes:
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


# ------------------------------------------------------------------ HTTP server

_REASONS = {200: "OK", 400: "Bad Request", 404: "Not Found", 408: "Request Timeout",
            503: "Service Unavailable",
            411: "Length Required", 413: "Payload Too Large", 414: "URI Too Long",
            431: "Request Header Fields Too Large", 501: "Not Implemented",
            505: "HTTP Version Not Supported"}
_RPC_PATHS = ("/", "/RPC2")


class _HttpError(Exception):
    def __init__(self, status: int, detail: str = "") -> None:
        super().__init__(detail or _REASONS.get(status, ""))
        self.status = status


def _status_response(status: int, detail: str) -> bytes:
    body = f"{status} {_REASONS.get(status, 'Error')}: {detail}\n".encode("utf-8", "replace")
    head = (f"HTTP/1.1 {status} {_REASONS.get(status, 'Error')}\r\nServer: minros\r\n"
            f"Content-Type: text/plain\r\nContent-Length: {len(body)}\r\nConnection: close\r\n\r\n")
    return head.encode("latin-1") + body


_logger = logging.getLogger("minros.xmlrpc")
#: per connection thread: the hooks of the request being handled (None outside a request)
_request = threading.local()


def after_reply(hook: Callable[[], Any]) -> None:
    """Run ``hook()`` once the reply to the request being handled has been sent, in the same
    thread. An API method that ends the server (``shutdown``) uses it, so that its own reply
    still reaches the caller without a grace sleep. Outside a request, ``hook`` runs now."""
    hooks = getattr(_request, "after_reply", None)
    if hooks is None:
        hook()
    else:
        hooks.append(hook)


class XmlRpcServer:
    """Threaded XML-RPC server for ``handler`` (see module docstring).

    ``start()`` binds, listens and returns; ``port`` is then the bound port. ``shutdown()`` closes
    the listening socket and every open connection.
    """

    def __init__(self, handler: Any, host: str = "", port: int = 0, *,
                 max_body: int = DEFAULT_MAX_BODY, idle_timeout: float = DEFAULT_IDLE_TIMEOUT,
                 max_connections: int = DEFAULT_MAX_CONNECTIONS, backlog: int = 1024,
                 ipv6: bool | None = None, body_budget: int | None = None) -> None:
        self.dispatcher = Dispatcher(handler)
        self.host = host
        self.requested_port = port
        self.max_body = max_body
        self.idle_timeout = idle_timeout
        self.max_connections = max_connections
        self.backlog = backlog
        self.ipv6 = (":" in host) if ipv6 is None else ipv6
        self._sock: socket.socket | None = None
        self._slots = threading.BoundedSemaphore(max_connections)
        self._conns: Dict[int, socket.socket] = {}
        #: connections waiting for their next request, and since when (reclaimable when full)
        self._idle_since: Dict[int, float] = {}
        self._conns_lock = threading.Lock()
        self._stopping = threading.Event()
        self._thread: threading.Thread | None = None
        self.body_budget = max(max_body, body_budget if body_budget is not None else 4 * max_body)
        self._budget_used = 0
        self._budget_cond = threading.Condition()
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
        for conn in conns:
            try:
                conn.shutdown(socket.SHUT_RDWR)
            except OSError:
                pass
        if self._thread is not None and self._thread is not threading.current_thread():
            self._thread.join(2.0)

    def _reserve(self, size: int) -> bool:
        with self._budget_cond:
            if not self._budget_cond.wait_for(
                    lambda: self._budget_used + size <= self.body_budget, timeout=self.idle_timeout):
                return False
            self._budget_used += size
            return True

    def _release(self, size: int) -> None:
        with self._budget_cond:
            self._budget_used -= size
            self._budget_cond.notify_all()

    def _reclaim_idle(self) -> None:
        with self._conns_lock:
            if not self._idle_since:
                return
            key = min(self._idle_since, key=self._idle_since.__getitem__)
            del self._idle_since[key]
            conn = self._conns.get(key)
        if conn is not None:
            try:
                conn.shutdown(socket.SHUT_RDWR)
            except OSError:
                pass

    def connection_count(self) -> int:
        with self._conns_lock:
            return len(self._conns)

    # -- accepting

    def _accept_loop(self) -> None:
        sock = self._sock
        assert sock is not None
        while not self._stopping.is_set():
            # Bound the connection threads. When all are taken, close the connection that has
            # waited longest for its next request (clients reopen a kept-alive connection the
            # server closed: Python's and roscpp's XML-RPC clients retry once), so that a crowd
            # of idle or silent clients cannot lock new ones out.
            while not self._slots.acquire(timeout=0.05):
                if self._stopping.is_set():
                    return
                self._reclaim_idle()
            try:
                conn, _addr = sock.accept()
            except OSError:
                self._slots.release()
                if self._stopping.is_set():
                    return
                # e.g. EMFILE (out of file descriptors): back off instead of spinning
                self._stopping.wait(0.05)
                continue
            try:
                conn.setsockopt(socket.IPPROTO_TCP, socket.TCP_NODELAY, 1)
                conn.settimeout(self.idle_timeout)
                with self._conns_lock:
                    self._conns[id(conn)] = conn
                threading.Thread(target=self._serve_connection, args=(conn,), daemon=True,
                                 name=f"xmlrpc-conn:{self.port}").start()
            except BaseException:  # noqa: BLE001 - e.g. cannot start a thread: drop this client
                with self._conns_lock:
                    self._conns.pop(id(conn), None)
                conn.close()
                self._slots.release()

    # -- one connection, many requests (keep-alive)

    def _serve_connection(self, conn: socket.socket) -> None:
        reader = conn.makefile("rb", buffering=65536)
        try:
            while not self._stopping.is_set():
                try:
                    request = self._read_request(reader, conn)
                except _HttpError as err:
                    try:
                        conn.sendall(_status_response(err.status, str(err)))
                    except OSError:
                        pass
                    return
                if request is None:
                    return
                body, keep_alive = request
                hooks: List[Callable[[], Any]] = []
                _request.after_reply = hooks
                try:
                    payload = self.dispatcher.handle_request_body(body)
                finally:
                    _request.after_reply = None
                    self._release(len(body))
                    del body
                head = ("HTTP/1.1 200 OK\r\nServer: minros\r\nContent-type: text/xml\r\n"
                        f"Content-length: {len(payload)}\r\n"
                        + ("" if keep_alive else "Connection: close\r\n") + "\r\n")
                try:
                    conn.sendall(head.encode("latin-1") + payload)
                finally:
                    for hook in hooks:
                        try:
                            hook()
                        except Exception:  # noqa: BLE001 - a hook must not end the connection thread
                            _logger.exception("after-reply hook failed")
                if not keep_alive:
                    return
        except (OSError, ValueError):
            pass  # peer went away, idle timeout, or shutdown
        finally:
            try:
                reader.close()
            except OSError:
                pass
            try:
                conn.close()
            except OSError:
                pass
            with self._conns_lock:
                self._conns.pop(id(conn), None)
            self._slots.release()

    def _read_request(self, reader: Any, conn: socket.socket) -> Tuple[bytes, bool] | None:
        """Read one request; ``None`` when the peer closed between requests or stayed idle."""
        key = id(conn)
        with self._conns_lock:
            self._idle_since[key] = time.monotonic()
        try:
            line = reader.readline(MAX_HEADER_LINE + 1)
            while line in (b"\r\n", b"\n"):  # tolerate stray blank lines between requests
                line = reader.readline(MAX_HEADER_LINE + 1)
        except socket.timeout:
            return None
        finally:
            with self._conns_lock:
                self._idle_since.pop(key, None)
        if not line:
            return None
        if len(line) > MAX_HEADER_LINE:
            raise _HttpError(414, "request line too long")
        parts = line.decode("latin-1").split()
        if len(parts) != 3:
            raise _HttpError(400, f"bad request line {line[:80]!r}")
        verb, path, version = parts
        if not version.startswith("HTTP/1."):
            raise _HttpError(505, version)
        headers: Dict[str, str] = {}
        for _ in range(MAX_HEADER_LINES + 1):
            hline = reader.readline(MAX_HEADER_LINE + 1)
            if len(hline) > MAX_HEADER_LINE:
                raise _HttpError(431, "header line too long")
            if hline in (b"\r\n", b"\n", b""):
                break
            key, sep, value = hline.decode("latin-1").partition(":")
            if not sep:
                raise _HttpError(400, "malformed header line")
            headers[key.strip().lower()] = value.strip()
        else:
            raise _HttpError(431, "too many header lines")
        if verb != "POST":
            raise _HttpError(501, f"Unsupported method ({verb!r})")
        if path.split("?", 1)[0] not in _RPC_PATHS:
            raise _HttpError(404, path)
        if "chunked" in headers.get("transfer-encoding", "").lower():
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
        if length > self.max_body:
            raise _HttpError(413, f"body of {length} bytes exceeds the limit of {self.max_body}")
        # Bodies in memory at once are bounded too, not only each one: wait for room, briefly.
        if not self._reserve(length):
            raise _HttpError(503, "server busy with large requests, try again")
        if headers.get("expect", "").lower() == "100-continue" and version != "HTTP/1.0":
            conn.sendall(b"HTTP/1.1 100 Continue\r\n\r\n")  # curl & co. wait for it
        try:
            body = reader.read(length)
        except BaseException:
            self._release(length)
            raise
        if len(body) != length:
            self._release(length)
            return None  # peer closed mid-body
        connection = headers.get("connection", "").lower()
        if version == "HTTP/1.0":
            keep_alive = "keep-alive" in connection
        else:
            keep_alive = "close" not in connection
        return body, keep_alive


# ------------------------------------------------------------------ client


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
    result; faults raise :class:`xmlrpc.client.Fault`, HTTP errors :class:`ProtocolError`,
    network failures and timeouts :class:`OSError`.
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
                try:
                    return self._single_request(request)
                except (ConnectionResetError, ConnectionAbortedError, BrokenPipeError,
                        _PeerClosed):
                    self._drop()
                    # A kept-alive connection the server closed while idle: retry once afresh.
                    if attempt or not reused:
                        raise
                except BaseException:
                    self._drop()
                    raise
        raise AssertionError("unreachable")

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

    def _single_request(self, request: bytes) -> Any:
        if self._sock is None:
            sock = socket.create_connection(self._address, timeout=self.timeout)
            sock.setsockopt(socket.IPPROTO_TCP, socket.TCP_NODELAY, 1)
            self._sock = sock
            self._reader = sock.makefile("rb", buffering=65536)
        self._sock.sendall(request)
        reader = self._reader
        status_line = reader.readline(MAX_HEADER_LINE + 1)
        if not status_line:
            raise _PeerClosed("connection closed by the server")
        parts = status_line.decode("latin-1").split(None, 2)
        if len(parts) < 2 or not parts[0].startswith("HTTP/") or not parts[1].isdigit():
            raise ProtocolError(self.uri, 0, f"bad status line {status_line[:80]!r}", {})
        status = int(parts[1])
        reason = parts[2].strip() if len(parts) > 2 else ""
        headers: Dict[str, str] = {}
        for _ in range(MAX_HEADER_LINES + 1):
            line = reader.readline(MAX_HEADER_LINE + 1)
            if line in (b"\r\n", b"\n", b""):
                break
            key, _sep, value = line.decode("latin-1").partition(":")
            headers[key.strip().lower()] = value.strip()
        else:
            raise ProtocolError(self.uri, status, "too many header lines", headers)
        length_text = headers.get("content-length")
        close = ("close" in headers.get("connection", "").lower()
                 or parts[0] == "HTTP/1.0" and "keep-alive" not in headers.get("connection", "").lower())
        if length_text is None:
            data = reader.read(self.max_body + 1)  # body delimited by the end of the connection
            close = True
        else:
            try:
                length = int(length_text)
            except ValueError:
                raise ProtocolError(self.uri, status, "bad Content-Length", headers) from None
            if length < 0 or length > self.max_body:
                raise ProtocolError(self.uri, 413, "response too large", headers)
            data = reader.read(length)
            if len(data) != length:
                raise _PeerClosed("connection closed mid-response")
        if close:
            self._drop()
        if len(data) > self.max_body:
            raise ProtocolError(self.uri, 413, "response too large", headers)
        if status != 200:
            self._drop()
            raise ProtocolError(self.uri, status, reason, headers)
        _check_markup(data)
        result, _ = xmlrpc.client.loads(data, use_builtin_types=False)
        return result[0] if len(result) == 1 else result


class _PeerClosed(ConnectionError):
    """The server closed a kept-alive connection before answering."""
