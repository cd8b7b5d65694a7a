"""The ``minros web`` server: one port for rosbridge, Foxglove, the video endpoints and the page.

Built on the threading server of ``websockets`` (one thread per connection, like the rest of
minros). A connection is told apart by:

* the WebSocket subprotocol: ``foxglove.websocket.v1`` -> :class:`FoxgloveSession`;
  ``minros.page.v1`` (the page at ``/``) -> :class:`~minros.web.page.PageSession`; no (or any
  other) subprotocol -> :class:`RosbridgeSession` (roslibjs and roslibpy ask for none);
* for plain HTTP (no ``Upgrade``), the path: ``/stream``, ``/snapshot``, ``/stream_viewer``,
  ``/streams`` (web_video_server's endpoints), ``/pkg/<package>/<path>`` (a mesh or texture of
  a ROS package, for the 3D view: ``package://<package>/<path>`` under
  :mod:`minros.web.assets`' rules, which Foxglove's ``fetchAsset`` follows too), else the static
  files of ``minros/web/static``.

Each WebSocket client has an :class:`~minros.web.outbox.Outbox` and a writer thread: ROS
callbacks only queue, the writer encodes and sends. A watchdog closes a client whose send has
been blocked for ``send_timeout`` seconds (a client that stopped reading); MJPEG viewers write
with the same bound. Every request first passes the Host and Origin checks of
:mod:`minros.web.origin` (no page of another site may drive the server; ``--allow-origin``
opens it to named ones). With a token, every request (WebSocket or HTTP) must carry it, as
``?token=`` in the URL or an ``Authorization: Bearer`` header, except the page's scripts and
styles (:data:`PUBLIC_ASSETS`), which hold nothing of the ROS system.

Connections are admitted as in every minros server (:mod:`minros.wire.admission`), by a small
guard around the websockets handler: ROS_ALLOWED_HOSTS, a cap that closes the idlest
connection when full, a per-peer share. A request counts as busy while it is answered; a
WebSocket session or an MJPEG stream counts as idle between messages, each message in either
direction renewing it, so at the cap (or over a peer's share) the session that has done
nothing for longest is closed and a new client always gets in. websockets' own options do
the rest: ``open_timeout`` is a deadline for the whole opening handshake, ``max_size`` refuses
a frame from its announced length, and frames are buffered as their bytes arrive.
"""

from __future__ import annotations

import hmac
import itertools
import logging
import mimetypes
import posixpath
import select
import socket
import threading
import time
import traceback
import urllib.parse
from pathlib import Path
from typing import Any, Dict, Iterable, Iterator, List, Optional, Sequence, Tuple

import minros
from minros import rosenv
from minros.web import assets, video
from minros.web import foxglove_protocol as fp
from minros.web.foxglove import FoxgloveSession
from minros.web.learning import LearnHub
from minros.web.origin import OriginPolicy
from minros.web.outbox import Outbox
from minros.web.page import SUBPROTOCOL as PAGE_SUBPROTOCOL
from minros.web.page import PageHub, PageSession
from minros.web.rosbridge import RosbridgeSession
from minros.web.state import WebState
from minros.web.wiretrace import WireFeed
from minros.wire import admission

STATIC_DIR = Path(__file__).resolve().parent / "static"
#: paths of the page's code and styles, served without the token
PUBLIC_ASSETS = ("/js/", "/vendor/", "/page.css")
DEFAULT_PORT = 9090
DEFAULT_MAX_MESSAGE_SIZE = 64 << 20
DEFAULT_SEND_TIMEOUT = 10.0
#: browsers and Foxglove open a few connections each; the handshake of each must end in 10 s
WEB_LIMITS = admission.Limits(max_connections=512, head_timeout=10.0)
#: seconds between two renewals of a session's activity (admission's idleness)
ACTIVITY_INTERVAL = 0.5
#: content types of the mesh files /pkg/ serves that mimetypes does not know
_MESH_TYPES = {"stl": "model/stl", "dae": "model/vnd.collada+xml", "obj": "model/obj",
               "mtl": "model/mtl", "urdf": "application/xml", "xacro": "application/xml"}


class _OneLine(logging.Filter):
    """websockets' own log lines, without tracebacks (expected network errors are not bugs)."""

    def filter(self, record: logging.LogRecord) -> bool:
        if record.exc_info and record.exc_info[1] is not None:
            record.msg = f"{record.getMessage()}: {record.exc_info[1]}"
            record.args = None
        record.exc_info = None
        return True


def _ws_logger() -> logging.Logger:
    logger = logging.getLogger("minros.web.websockets")
    if not logger.filters:
        logger.addFilter(_OneLine())
        logger.setLevel(logging.CRITICAL)  # connection-level failures are reported by us
    return logger


def send_with_timeout(sock: socket.socket, parts: List[bytes], timeout: float) -> None:
    """Write ``parts`` to a blocking socket without blocking longer than ``timeout`` seconds
    at a time (another thread reads the same socket, so its timeout cannot be changed)."""
    for part in parts:
        view = memoryview(part)
        while len(view):
            try:
                sent = sock.send(view, socket.MSG_DONTWAIT)
            except BlockingIOError:
                sent = 0
            if sent:
                view = view[sent:]
                continue
            _, writable, _ = select.select([], [sock], [], timeout)
            if not writable:
                raise TimeoutError(f"the viewer read nothing for {timeout:.0f} s")


class _Client:
    """One WebSocket client: its outbox, its writer thread, its session."""

    def __init__(self, server: WebServer, connection: Any, client_id: str) -> None:
        self.server = server
        self.connection = connection
        self.id = client_id
        self.outbox = Outbox()
        self.send_started: Optional[float] = None
        self.closing: Optional[str] = None
        self.session: Any = None
        #: the connection's admission key and when it last told admission it was active
        self.key: Optional[int] = None
        self.touched = 0.0
        self.writer = threading.Thread(target=self._write_loop, name=f"minros-web-writer:{client_id}",
                                       daemon=True)

    def touch(self) -> None:
        """Something went in or out: renew the session's activity (at most twice a second)."""
        now = time.monotonic()
        if now - self.touched >= ACTIVITY_INTERVAL:
            self.touched = now
            self.server.guard_active(self.key)

    def close(self, reason: str) -> None:
        """Drop the client (from any thread): one log line, the socket shut down."""
        if self.closing is not None:
            return
        self.closing = reason
        minros.logwarn(f"[web] closing client {self.id}: {reason}")
        self.outbox.close()
        try:
            self.connection.socket.shutdown(socket.SHUT_RDWR)
        except OSError:
            pass

    def _write_loop(self) -> None:
        from websockets.exceptions import ConnectionClosed

        send = self.connection.send
        get = self.outbox.get
        while True:
            got = get()
            if got is None:
                return
            slot, item = got
            try:
                # a frame, or an iterable of them: rosbridge's fragments are made one at a time
                frames = item if slot is None else slot.render(item)
                if isinstance(frames, (str, bytes, bytearray, memoryview)):
                    frames = [frames]
            except Exception as exc:
                minros.logerr(f"[web] client {self.id}: cannot encode a message for "
                              f"{slot.key if slot else 'reply'}: {exc}")
                continue
            try:
                if isinstance(frames, assets.Fragments):
                    send(self._paced(frames))
                    self.send_started = None
                else:
                    for frame in frames:
                        self.send_started = time.monotonic()
                        send(frame)
                        self.send_started = None
            except (ConnectionClosed, OSError):
                self.send_started = None
                return
            except assets.AssetError as exc:  # websockets has failed the connection (1011)
                self.send_started = None
                self.close(f"a file could not be sent: {exc}")
                return
            self.touch()

    def _paced(self, fragments: Iterable[Any]) -> Iterator[Any]:
        """The fragments of one message, the watchdog's clock restarted at each (a long
        message to a client that keeps reading is not a stalled send)."""
        for fragment in fragments:
            self.send_started = time.monotonic()
            yield fragment
            self.touch()


class _Guard:
    """Admission in front of websockets' per-connection handler: the allow-list, the cap and
    the per-peer share of :class:`minros.wire.admission.Admission`. A connection is evictable
    while its request arrives, busy while it is answered (``served``), then, as a session or
    a stream, idle since its last message (``active``): the idlest goes first."""

    def __init__(self, inner: Any, server: Any, allowed: Any) -> None:
        self.inner = inner
        self.server = server
        self.admission = admission.Admission(WEB_LIMITS, allowed, what="minros web")
        self._socks: Dict[int, socket.socket] = {}
        self._keys: Dict[socket.socket, int] = {}
        self._lock = threading.Lock()

    def __call__(self, sock: socket.socket, addr: Any) -> None:
        adm = self.admission
        key = adm.new_key()
        try:
            local = sock.getsockname()
            victims = adm.admit(key, addr[0], local[0] if isinstance(local, tuple) else None)
        except (admission.Refused, OSError) as exc:
            if isinstance(exc, admission.Refused):
                if exc.report:
                    minros.logwarn(f"[web] {exc}")
                _refuse(sock, exc.status, str(exc))
            else:
                sock.close()
            with self.server.lock:  # what websockets' handler does on its way out
                self.server.handler_threads.discard(threading.current_thread())
            return
        adm.set_state(key, admission.READING)
        for victim in victims:
            with self._lock:
                other = self._socks.get(victim)
            if other is not None:
                try:
                    other.shutdown(socket.SHUT_RDWR)
                except OSError:
                    pass
        with self._lock:
            self._socks[key] = sock
            self._keys[sock] = key
        try:
            self.inner(sock, addr)
        finally:
            with self._lock:
                self._socks.pop(key, None)
                self._keys.pop(sock, None)
            adm.leave(key)

    def key_of(self, sock: socket.socket) -> Optional[int]:
        with self._lock:
            return self._keys.get(sock)

    def served(self, sock: socket.socket) -> None:
        """The connection's request is in and being answered: not evicted meanwhile."""
        key = self.key_of(sock)
        if key is not None:
            self.admission.set_state(key, admission.BUSY)

    def active(self, key: Optional[int]) -> None:
        """An established session or stream did something now: idle from now on, so it is
        evicted after every connection that has been quiet for longer."""
        if key is not None:
            self.admission.set_state(key, admission.IDLE)

    def evicted(self, key: Optional[int]) -> bool:
        return key is not None and self.admission.evicted(key)


def _header(request: Any, name: str) -> Optional[str]:
    """The one value of header ``name`` (None when absent); ValueError when repeated."""
    values = request.headers.get_all(name)
    if len(values) > 1:
        raise ValueError(f"the request has {len(values)} {name} headers: send one")
    return values[0] if values else None


def _local_names(bound: str) -> List[str]:
    """The names this machine answers to in a Host header, besides its addresses and
    localhost: its host name (and the mDNS ``.local`` one), ROS_HOSTNAME / ROS_IP, and the
    address ``--host`` names."""
    names = [bound, rosenv.get_address_override() or ""]
    try:
        hostname = socket.gethostname()
    except OSError:
        hostname = ""
    if hostname:
        names += [hostname, hostname.split(".")[0] + ".local"]
    return [n for n in names if n]


def _refuse(sock: socket.socket, status: int, reason: str) -> None:
    body = (reason + "\n").encode("utf-8", "replace")
    try:
        sock.settimeout(1.0)
        sock.sendall(f"HTTP/1.1 {status} {'Forbidden' if status == 403 else 'Service Unavailable'}"
                     f"\r\nContent-Type: text/plain; charset=utf-8\r\nContent-Length: {len(body)}"
                     "\r\nConnection: close\r\n\r\n".encode("latin-1") + body)
    except OSError:
        pass
    sock.close()


class WebServer:
    """Serves rosbridge, Foxglove, video and static files on one port (see the module doc)."""

    def __init__(self, state: WebState, host: str = "127.0.0.1", port: int = DEFAULT_PORT,
                 token: Optional[str] = None, name: str = "minros web", rosapi: Any = None,
                 send_timeout: float = DEFAULT_SEND_TIMEOUT,
                 max_message_size: int = DEFAULT_MAX_MESSAGE_SIZE, compression: bool = False,
                 static_dir: Path = STATIC_DIR, trace: Sequence[str] = (),
                 allow_origins: Sequence[str] = (),
                 asset_allowlist: Sequence[str] = assets.DEFAULT_ALLOWLIST,
                 learn_dir: Optional[str] = None) -> None:
        self.state = state
        self.host = host
        self.port = port
        self.token = token or None
        self.name = name
        self.rosapi = rosapi
        self.send_timeout = send_timeout
        self.max_message_size = max_message_size
        self.compression = compression
        self.static_dir = static_dir
        self.clients: Dict[str, _Client] = {}
        #: the wire traces followed for the page's Wire view (``--trace``)
        self.wire = WireFeed(trace) if trace else None
        #: the exercise a page started (the Learn view), in minros learn's folder (or --learn-dir)
        self.learn = LearnHub(Path(learn_dir) if learn_dir else None)
        self.page_hub = PageHub(state, self.wire, self.learn)
        self.viewers = 0
        self._ids = itertools.count(1)
        self._lock = threading.Lock()
        self._stop = threading.Event()
        self._server: Any = None
        self._guard: Any = None
        self._threads: List[threading.Thread] = []
        self._evicted = 0
        self._evicted_logged = -10.0
        self._slow_closed = 0
        self._slow_logged = -60.0
        self.allowed = rosenv.allowed_hosts()  # ValueError naming a malformed entry
        #: the Host and Origin checks (OriginError naming a malformed --allow-origin)
        self.origins = OriginPolicy(allow_origins, _local_names(host))
        self._refusals_logged: Dict[str, float] = {}
        #: which package files /pkg/ and Foxglove's fetchAsset serve (ValueError naming a
        #: pattern that does not parse)
        self.asset_patterns = assets.compile_allowlist(asset_allowlist)
        #: the bytes of package files in memory at once, for /pkg/ and fetchAsset together
        self.asset_budget = assets.Budget(report=lambda text: minros.logwarn(f"[web] {text}"))

    # -- lifecycle -------------------------------------------------------------------------

    def start(self) -> None:
        """Bind the port (OSError if taken) and serve in background threads."""
        from websockets.sync.server import serve

        self._server = serve(
            self._handle, self.host, self.port, process_request=self._process_request,
            select_subprotocol=self._select_subprotocol, server_header="minros web",
            compression="deflate" if self.compression else None,
            max_size=self.max_message_size, logger=_ws_logger(), ping_interval=20,
            ping_timeout=None, open_timeout=WEB_LIMITS.head_timeout, close_timeout=2)
        self._guard = _Guard(self._server.handler, self._server, self.allowed)
        self._server.handler = self._guard
        self.port = self._server.socket.getsockname()[1]
        if self.wire is not None:
            self.wire.start()
        for target, name in ((self._server.serve_forever, "minros-web-server"),
                             (self._watchdog, "minros-web-watchdog")):
            thread = threading.Thread(target=target, name=name, daemon=True)
            thread.start()
            self._threads.append(thread)

    def shutdown(self) -> None:
        self._stop.set()
        self.page_hub.stop()
        if self.wire is not None:
            self.wire.stop()
        if self._server is not None:
            for client in list(self.clients.values()):
                client.outbox.close()
            threading.Thread(target=self._server.shutdown, name="minros-web-shutdown",
                             daemon=True).start()

    @property
    def url(self) -> str:
        host = "localhost" if self.host in ("127.0.0.1", "::1", "localhost") else self.host
        if host in ("0.0.0.0", "", "::"):
            host = socket.gethostname()
        return f"http://{host}:{self.port}"

    def guard_active(self, key: Optional[int]) -> None:
        if self._guard is not None:
            self._guard.active(key)

    def _note_eviction(self, what: str) -> None:
        """One log line for the first session closed to make room, then at most one every 10 s
        with the count (a flood of connections must not flood the log)."""
        with self._lock:
            self._evicted += 1
            now = time.monotonic()
            if now - self._evicted_logged < 10.0:
                return
            count, self._evicted, self._evicted_logged = self._evicted, 0, now
        more = f" ({count} since the last report)" if count > 1 else ""
        minros.logwarn(f"[web] closed {what}, the idlest, to make room for a new connection "
                       f"(at most {WEB_LIMITS.max_connections}, "
                       f"{WEB_LIMITS.peer_connections} from one address){more}")

    def _watchdog(self) -> None:
        while not self._stop.wait(0.5):
            now = time.monotonic()
            for client in list(self.clients.values()):
                started = client.send_started
                if started is not None and now - started > self.send_timeout:
                    client.close(f"it has not read anything for {self.send_timeout:.0f} s")

    # -- the handshake ---------------------------------------------------------------------

    @staticmethod
    def _select_subprotocol(connection: Any, offered: Any) -> Optional[str]:
        for known in (fp.SUBPROTOCOL, PAGE_SUBPROTOCOL):
            if known in offered:
                return known
        return None

    def _token_ok(self, request: Any, query: str) -> bool:
        if self.token is None:
            return True
        given = urllib.parse.parse_qs(query).get("token", [""])[0]
        auth = _header(request, "Authorization") or ""
        if not given and auth.lower().startswith("bearer "):
            given = auth[7:].strip()
        return hmac.compare_digest(given.encode(), self.token.encode())

    def _response(self, status: int, body: bytes, content_type: str = "text/plain; charset=utf-8",
                  headers: Optional[List[Any]] = None) -> Any:
        from http import HTTPStatus

        from websockets.datastructures import Headers
        from websockets.http11 import Response

        all_headers = Headers()
        for key, value in headers or []:
            all_headers[key] = value
        if "Content-Type" not in all_headers:
            all_headers["Content-Type"] = content_type
        all_headers["Content-Length"] = str(len(body))
        all_headers["Connection"] = "close"
        return Response(status, HTTPStatus(status).phrase, all_headers, body)

    def _text(self, status: int, text: str) -> Any:
        return self._response(status, (text + "\n").encode("utf-8"))

    def _refused_page(self, connection: Any, status: int, text: str) -> Any:
        """A 403 (or 400) of the Host and Origin checks, logged at most once a minute per
        reason (a page may retry every second)."""
        now = time.monotonic()
        if now - self._refusals_logged.get(text, -60.0) >= 60.0:
            if len(self._refusals_logged) > 256:
                self._refusals_logged.clear()
            self._refusals_logged[text] = now
            peer = connection.remote_address
            reason = text.removeprefix("minros web: ")
            minros.logwarn(f"[web] {peer[0] if peer else '?'}: {reason}")
        return self._text(status, text)

    def _process_request(self, connection: Any, request: Any) -> Any:
        self._guard.served(connection.socket)
        try:
            host = _header(request, "Host")
            origin = _header(request, "Origin")
            upgrade = (_header(request, "Upgrade") or "").lower() == "websocket"
        except ValueError as exc:
            return self._refused_page(connection, 400, f"minros web: {exc}")
        refusal = self.origins.host_error(host) or self.origins.origin_error(origin, host)
        if refusal is not None:
            return self._refused_page(connection, 403, refusal)
        path, _, query = request.path.partition("?")
        if any(ord(c) < 0x20 or ord(c) == 0x7F for c in urllib.parse.unquote(path)):
            return self._text(400, "minros web: the path holds a control character (such as "
                                   "%00): no page or endpoint has one")
        if not upgrade and posixpath.normpath(urllib.parse.unquote(path)).startswith(PUBLIC_ASSETS):
            # the page's code is the same in every install: a browser fetches it without the
            # token (a module's imports carry no query); the page itself and every piece of
            # data (WebSocket, video) still need the token
            return self._static(path)
        try:
            token_ok = self._token_ok(request, query)
        except ValueError as exc:
            return self._refused_page(connection, 400, f"minros web: {exc}")
        if not token_ok:
            peer = connection.remote_address
            minros.logwarn(f"[web] refused {peer[0] if peer else '?'}: wrong or missing token")
            return self._text(401, "minros web: wrong or missing token. Add ?token=TOKEN to the "
                                   "URL (the token `minros web --token` was started with).")
        if upgrade:
            return None
        cors = self.origins.cors_origin(origin, host)
        try:
            response = self._http(connection, path, query, cors)
        except video.VideoError as exc:
            response = self._text(exc.status, f"minros web: {exc}")
        if cors is not None:  # a page that may use the server may read its answers
            response.headers["Access-Control-Allow-Origin"] = cors
            response.headers["Vary"] = "Origin"
        return response

    # -- plain HTTP ------------------------------------------------------------------------

    def _token_query(self, query: str) -> str:
        token = urllib.parse.parse_qs(query).get("token", [""])[0]
        return "&token=" + urllib.parse.quote(token) if token else ""

    def _http(self, connection: Any, path: str, query: str, cors: Optional[str]) -> Any:
        """``cors``: the origin of a page allowed to read the answer, for the stream (whose
        head is written here); a page of another site may show the images, not read them."""
        if path == "/stream":
            cors_headers = [("Access-Control-Allow-Origin", cors), ("Vary", "Origin")] if cors else []
            return self._stream(connection, self._video_params(query), cors_headers)
        if path == "/snapshot":
            params = self._video_params(query)
            feed = self._feed(params.topic)
            try:
                seq = feed.wait(0, 5.0)
                if not seq:
                    raise video.VideoError(f"no image arrived on {params.topic} within 5 s: is "
                                           "anything publishing it?", 503)
                _seq, jpeg, stamp = feed.jpeg(params)
            finally:
                self._release_feed(params.topic)
            return self._response(200, jpeg, "image/jpeg", video.snapshot_headers(stamp))
        if path == "/stream_viewer":
            params = self._video_params(query)
            return self._response(200, video.viewer_page(params, query).encode(),
                                  "text/html; charset=utf-8")
        if path.startswith("/pkg/"):
            return self._package_file(connection, path, cors)
        if path == "/streams":
            graph = self.state.refresh_graph()
            topics = [t for t, ty in graph.topic_types.items() if video.is_image_type(ty)]
            return self._response(200, video.list_page(topics, self._token_query(query)).encode(),
                                  "text/html; charset=utf-8")
        return self._static(path)

    def _static(self, path: str) -> Any:
        relative = urllib.parse.unquote(path).lstrip("/") or "index.html"
        root = self.static_dir.resolve()
        try:
            target = (root / relative).resolve()
            found = root in target.parents and target.is_file()
        except (OSError, ValueError):  # a name too long for the file system, say
            found = False
        if not found:
            return self._text(404, f"minros web: no such page {path[:200]}")
        content_type = mimetypes.guess_type(target.name)[0] or "application/octet-stream"
        if content_type.startswith("text/") or content_type.endswith("javascript"):
            content_type += "; charset=utf-8"
        return self._response(200, target.read_bytes(), content_type)

    def _package_file(self, connection: Any, path: str, cors: Optional[str]) -> Any:
        """``/pkg/<package>/<path>``: the file ``package://<package>/<path>`` names, if the
        asset rules allow it (the path stays percent-encoded: the rules decode it), written
        on the socket as it is read (:func:`assets.chunks`), within admission's time for
        its length; this runs in the connection's own thread."""
        uri = assets.PACKAGE_PREFIX + path[len("/pkg/"):]
        try:
            stream, size = assets.open_file(assets.resolve(uri, self.asset_patterns), uri)
        except assets.AssetError as exc:
            return self._text(exc.status, f"minros web: {exc}")
        suffix = uri.rsplit(".", 1)[-1].lower()
        content_type = (_MESH_TYPES.get(suffix) or mimetypes.guess_type("x." + suffix)[0]
                        or "application/octet-stream")
        head = [f"HTTP/1.1 200 OK\r\nServer: minros web\r\nContent-Type: {content_type}\r\n",
                f"Content-Length: {size}\r\nCache-Control: no-cache\r\nConnection: close\r\n"]
        if cors is not None:
            head.append(f"Access-Control-Allow-Origin: {cors}\r\nVary: Origin\r\n")
        sock = connection.socket
        peer = connection.remote_address[0] if connection.remote_address else ""
        deadline = time.monotonic() + WEB_LIMITS.transfer_time(size)
        started = False
        try:
            with stream:
                pending = ["".join(head).encode("latin-1") + b"\r\n"]
                for chunk in assets.chunks(stream, size, self.asset_budget, peer,
                                           self.send_timeout):
                    left = deadline - time.monotonic()
                    if left <= 0:
                        raise TimeoutError(f"{size} bytes take longer than "
                                           f"{WEB_LIMITS.transfer_time(size):.0f} s")
                    started = True
                    send_with_timeout(sock, [*pending, chunk], min(self.send_timeout, left))
                    pending = []
                if pending:  # an empty file
                    send_with_timeout(sock, pending, self.send_timeout)
        except assets.AssetError as exc:  # no room in the budget
            if not started:
                return self._text(exc.status, f"minros web: {exc}")
        except TimeoutError as exc:
            self._note_slow_download(peer, uri, str(exc))
        except OSError:
            pass  # the client went away
        try:
            sock.shutdown(socket.SHUT_RDWR)
        except OSError:
            pass
        return self._text(200, "")  # not delivered: the socket is shut down

    def _note_slow_download(self, peer: str, uri: str, why: str) -> None:
        """One line for a download closed for not being read, then at most one a minute."""
        now = time.monotonic()
        with self._lock:
            if now - self._slow_logged < 60.0:
                self._slow_closed += 1
                return
            count, self._slow_closed, self._slow_logged = self._slow_closed, 0, now
        more = f" ({count} more since the last report)" if count else ""
        minros.logwarn(f"[web] closed the download of {uri[:200]} to {peer}: {why}{more}")

    # -- video -----------------------------------------------------------------------------

    def _video_params(self, query: str) -> video.StreamParams:
        params = video.parse_params(query)
        type_name = self.state.topic_type(params.topic)
        if params.type == "ros_compressed":
            compressed = params.topic.rstrip("/") + "/compressed"
            if self.state.topic_type(compressed) == video.COMPRESSED:
                params = video.StreamParams(compressed, params.width, params.height,
                                            params.quality, params.invert, params.type)
                type_name = video.COMPRESSED
        if type_name is not None and not video.is_image_type(type_name):
            raise video.VideoError(f"{params.topic} is a {type_name}, not a sensor_msgs/Image "
                                   "or CompressedImage", 415)
        return params

    def _feed(self, topic: str) -> video.ImageFeed:
        with self._lock:
            feed = self.state.feeds.get(topic)
            if feed is None:
                feed = video.ImageFeed(topic)
                self.state.feeds[topic] = feed
                self.state.tap(topic, self.state.topic_type(topic), ("video", topic), feed.push)
            feed.viewers += 1
            return feed

    def _release_feed(self, topic: str) -> None:
        with self._lock:
            feed = self.state.feeds.get(topic)
            if feed is None:
                return
            feed.viewers -= 1
            if feed.viewers <= 0:
                del self.state.feeds[topic]
                self.state.untap(topic, ("video", topic))

    def _stream(self, connection: Any, params: video.StreamParams,
                extra_headers: Sequence[Tuple[str, str]] = ()) -> Any:
        """Write an MJPEG stream on the connection's socket until the viewer goes away (this
        runs in the connection's own thread; the websockets handshake is never completed)."""
        feed = self._feed(params.topic)
        sock = connection.socket
        reader = getattr(connection, "recv_events_thread", None)
        key = self._guard.key_of(sock)
        with self._lock:
            self.viewers += 1
        try:
            send_with_timeout(sock, [video.stream_head(extra_headers)], self.send_timeout)
            self._guard.active(key)
            seq = 0
            touched = time.monotonic()
            while not self._stop.is_set():
                newest = feed.wait(seq, 1.0)
                if reader is not None and not reader.is_alive():
                    break  # the viewer closed its end (or was closed to make room)
                if newest == seq:
                    continue
                seq, jpeg, stamp = feed.jpeg(params)
                send_with_timeout(sock, video.stream_part(jpeg, stamp), self.send_timeout)
                if time.monotonic() - touched >= ACTIVITY_INTERVAL:
                    touched = time.monotonic()
                    self._guard.active(key)
        except TimeoutError as exc:
            minros.logwarn(f"[web] closing the stream of {params.topic}: {exc}")
        except video.VideoError as exc:
            minros.logwarn(f"[web] stream of {params.topic} stopped: {exc}")
        except OSError:
            pass  # the viewer went away
        finally:
            if self._guard.evicted(key):
                self._note_eviction(f"the stream of {params.topic} to {connection.remote_address}")
            with self._lock:
                self.viewers -= 1
            self._release_feed(params.topic)
            try:
                sock.shutdown(socket.SHUT_RDWR)
            except OSError:
                pass
        return self._text(200, "")  # not delivered: the socket is shut down

    # -- WebSocket clients -----------------------------------------------------------------

    def _local_page(self, connection: Any) -> bool:
        """The page is of this machine (may start exercises): see OriginPolicy.local_page."""
        request = getattr(connection, "request", None)
        if request is None:
            return False
        try:
            return self.origins.local_page(_header(request, "Origin"), _header(request, "Host"))
        except ValueError:
            return False

    def _handle(self, connection: Any) -> None:
        from websockets.exceptions import ConnectionClosed

        peer = connection.remote_address
        client_id = f"{peer[0]}:{peer[1]}#{next(self._ids)}" if peer else str(next(self._ids))
        client = _Client(self, connection, client_id)
        foxglove = connection.subprotocol == fp.SUBPROTOCOL
        page = connection.subprotocol == PAGE_SUBPROTOCOL
        kind = "Foxglove" if foxglove else "page" if page else "rosbridge"
        if foxglove:
            client.session = FoxgloveSession(client_id, self.state, client.outbox, client.close,
                                             server_name=self.name,
                                             asset_patterns=self.asset_patterns,
                                             asset_budget=self.asset_budget,
                                             peer=peer[0] if peer else "",
                                             asset_timeout=self.send_timeout)
        elif page:
            client.session = PageSession(client_id, self.state, client.outbox, client.close,
                                         self.page_hub, rosapi=self.rosapi,
                                         local=self._local_page(connection))
        else:
            client.session = RosbridgeSession(client_id, self.state, client.outbox, client.close,
                                              rosapi=self.rosapi)
        client.key = self._guard.key_of(connection.socket)
        client.touch()
        with self._lock:
            self.clients[client_id] = client
        minros.loginfo(f"[web] {kind} client {client_id} connected")
        client.writer.start()
        try:
            if foxglove or page:
                client.session.start()
            while True:
                data = connection.recv()
                client.touch()
                try:
                    client.session.receive(data)
                except Exception:
                    minros.logerr(f"[web] client {client_id}: internal error\n{traceback.format_exc()}")
        except ConnectionClosed:
            pass
        finally:
            sent = getattr(connection.protocol, "close_sent", None)
            if sent is not None and sent.code == 1009:  # websockets refused a frame over max_size
                minros.logwarn(f"[web] closed client {client_id}: it sent a message larger than "
                               f"{self.max_message_size} bytes (raise --max-message-size)")
            if self._guard.evicted(client.key):
                self._note_eviction(f"{kind} client {client_id}")
            with self._lock:
                self.clients.pop(client_id, None)
            client.outbox.close()
            try:
                client.session.close()
            except Exception:
                minros.logerr(f"[web] client {client_id}: cleanup failed\n{traceback.format_exc()}")
            client.writer.join(timeout=self.send_timeout + 1)
            minros.loginfo(f"[web] client {client_id} disconnected")
