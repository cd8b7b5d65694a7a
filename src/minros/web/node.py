"""Running ``minros web``: the node, rosapi's services, the server, until shutdown.

Used by ``minros web`` (minros.cli.web) and by the executables that roslaunch and rosrun find as
``rosbridge_server/rosbridge_websocket``, ``foxglove_bridge/foxglove_bridge`` and
``rosapi/rosapi_node`` (the launch files minros ships start those). Launched as a node, the
server reads its settings from private parameters, with rosbridge's and foxglove_bridge's
names: ``~port``, ``~address``, ``~topics_glob``, ``~services_glob``, ``~params_glob``,
``~max_message_size``, ``~unregister_timeout``, ``~use_compression``, plus ``~token`` and
``~allow_origin`` (``--allow-origin``: one origin, or a list) and foxglove_bridge's
``~asset_uri_allowlist`` (regular expressions of the ``package://`` and ``file://`` URLs the
page's 3D view and Foxglove's ``fetchAsset`` may read; see :mod:`minros.web.assets`; also read
by ``minros web``, as ``_asset_uri_allowlist:=...``). Once listening, the node sets
``~actual_port`` to the port it got, as rosbridge_websocket does (``~port`` 0 picks a free one).

``minros web`` refuses to start, in one line, when a live node already holds its name
(``/minros_web`` unless ``--name`` or ``__name:=`` says otherwise): by ROS's rule the new node
would shut the old one down, a server whose pages and clients would then lose it without a
word. A unique (anonymous) name would not do either: both servers would serve the same
``/rosapi/*`` services, the newer taking them over and, on exit, leaving the older without.
So a second server is a deliberate choice, ``--name``. The launch-file executables keep
ROS's rule: roslaunch users relaunch a node by its name.
"""

from __future__ import annotations

import signal
import sys
import threading
from dataclasses import dataclass, field
from typing import Any, List, Optional

import minros
from minros.signals import SignalWatch


@dataclass
class Settings:
    host: str = "127.0.0.1"
    port: int = 9090
    token: Optional[str] = None
    name: str = "minros_web"
    topics_glob: List[str] = field(default_factory=list)
    services_glob: List[str] = field(default_factory=list)
    params_glob: List[str] = field(default_factory=list)
    graph_interval: float = 1.0
    send_timeout: float = 10.0
    max_message_size: int = 64 << 20
    unregister_timeout: float = 10.0
    compression: bool = False
    server_name: str = "minros web"
    rosapi: bool = True
    server: bool = True
    trace: List[str] = field(default_factory=list)  # wire traces for the page's Wire view
    #: origins of pages from other sites allowed to use the server (--allow-origin)
    allow_origins: List[str] = field(default_factory=list)
    #: set ~actual_port once listening (the launch-file nodes, as rosbridge_websocket does)
    set_actual_port: bool = False
    #: the asset allow-list (None: minros.web.assets' default, or ~asset_uri_allowlist)
    asset_uri_allowlist: Optional[List[str]] = None
    #: the Learn view's exercises' folder (None: $MINROS_LEARN_DIR, else $ROS_HOME/learn)
    learn_dir: Optional[str] = None


def parse_globs(value: Any) -> List[str]:
    """rosapi's glob parameter: ``"[*]"``, ``"['/a/*', '/b']"`` or a YAML list."""
    if isinstance(value, list):
        items = [str(v) for v in value]
    else:
        text = str(value or "").strip().strip("[").strip("]")
        items = [part.strip().strip("'\"") for part in text.split(",")]
    items = [i for i in items if i]
    return [] if items == ["*"] else items


def register_rosapi(rosapi: Any) -> List[Any]:
    """Serve every rosapi service as a real ROS service of this node."""
    from minros.web.rosapi import SERVICES

    services = []
    for name in SERVICES:
        def handler(request: Any, _name: str = name) -> Any:
            return rosapi.handle(_name, request)
        services.append(minros.Service(name, rosapi.service_class(name), handler))
    return services


def master_error() -> Optional[str]:
    """Why the master cannot be used, or None."""
    from minros.tools.master import Master, MasterIOError

    master = Master("/minros_web")
    try:
        master.getPid()
        return None
    except MasterIOError:
        return (f"cannot reach the ROS master at {master.uri}: start one with `minros core` "
                "(or roscore), or set ROS_MASTER_URI")
    except Exception as exc:
        return f"the ROS master at {master.uri} does not answer: {exc}"
    finally:
        master.close()


def name_taken(name: str, argv: Optional[List[str]] = None) -> Optional[str]:
    """Why ``minros web`` must not take the node name ``name`` (``__name:=`` in ``argv``
    wins): a live node already holds it. None when it is free, or held by a node that no
    longer answers (a stale registration, which init_node replaces as rospy does)."""
    from minros import names
    from minros.tools.master import Master, MasterError, MasterIOError
    from minros.wire.slaveapi import RemoteError, SlaveClient

    argv = list(sys.argv if argv is None else argv)
    given = names.load_mappings(argv).get("__name", name)
    resolved = names.resolve_name(given, names.get_ros_namespace(argv=argv) + "unnamed")
    master = Master(resolved)
    try:
        uri = master.lookup_node(resolved)
    except (MasterError, MasterIOError):
        return None
    finally:
        master.close()
    try:
        with SlaveClient(uri, resolved, timeout=2.0) as node:
            pid = node.get_pid()
    except (OSError, RemoteError):
        return None
    return (f"a node named {resolved} is already running (pid {pid}, {uri}); another with its "
            "name would shut it down, as ROS does. Stop that one, or start this one under a "
            "name of its own: minros web --name minros_web2")


def run(settings: Settings, announce: Any = print, argv: Optional[List[str]] = None) -> int:
    """Start the node and the server; serve until Ctrl-C or a ROS shutdown. Exit status."""
    from minros.web.rosapi import Rosapi
    from minros.web.state import Options, WebState

    error = master_error()
    if error:
        print(f"minros web: error: {error}", file=sys.stderr)
        return 1
    # `minros web` (the node not yet started): refuse a name a live node holds. The
    # launch-file executables (run_node, already a node) keep ROS's rule instead.
    from minros.node import is_initialized

    if not is_initialized():
        taken = name_taken(settings.name, argv)
        if taken:
            print(f"minros web: error: {taken}", file=sys.stderr)
            return 1
    minros.init_node(settings.name, argv=argv, disable_signals=True)
    stop = threading.Event()
    SignalWatch(lambda _signum: stop.set(), "web-signals").install((signal.SIGINT, signal.SIGTERM))
    minros.on_shutdown(stop.set)
    state = WebState(Options(topics_glob=settings.topics_glob, services_glob=settings.services_glob,
                             params_glob=settings.params_glob, graph_interval=settings.graph_interval,
                             unregister_timeout=settings.unregister_timeout))
    rosapi = Rosapi(state, settings.topics_glob, settings.services_glob, settings.params_glob)
    allowlist = settings.asset_uri_allowlist
    if allowlist is None:
        allowlist = asset_allowlist(minros.get_param("~asset_uri_allowlist", None))
    if settings.rosapi:
        register_rosapi(rosapi)
    server = None
    if settings.server:
        from minros.web.server import WebServer

        try:  # a malformed ROS_ALLOWED_HOSTS or ~allow_origin
            server = WebServer(state, settings.host, settings.port, token=settings.token,
                               name=settings.server_name, rosapi=rosapi,
                               send_timeout=settings.send_timeout,
                               max_message_size=settings.max_message_size,
                               compression=settings.compression, trace=settings.trace,
                               allow_origins=settings.allow_origins, asset_allowlist=allowlist,
                               learn_dir=settings.learn_dir)
        except ValueError as exc:
            print(f"minros web: error: {exc}", file=sys.stderr)
            minros.signal_shutdown("bad settings")
            return 2
        try:
            server.start()
        except OSError as exc:
            print(f"minros web: error: cannot listen on {settings.host}:{settings.port}: "
                  f"{exc.strerror or exc}. Is another server using that port? Pick another "
                  "with --port.", file=sys.stderr)
            minros.signal_shutdown("port unavailable")
            return 1
        if settings.set_actual_port:
            minros.set_param("~actual_port", server.port)
    state.start()
    if server is not None:
        announce(_banner(server, settings))
    else:
        announce(f"rosapi: {len(rosapi_names())} services served by {minros.get_name()}")
    try:
        while not stop.wait(0.5):
            if minros.is_shutdown():
                break
    finally:
        if server is not None:
            server.shutdown()
        state.stop()
        minros.signal_shutdown("minros web stopped")
    return 0


def rosapi_names() -> List[str]:
    from minros.web.rosapi import SERVICES

    return list(SERVICES)


def _banner(server: Any, settings: Settings) -> str:
    url = server.url
    ws = url.replace("http://", "ws://")
    token = f"?token={settings.token}" if settings.token else ""
    return "\n".join([
        f"minros web: listening on {url}/{token} (node {minros.get_name()})",
        f"  the page               {url}/{token}   (graph, topics, plot, images, turtlesim, ...)",
        f"  rosbridge v2 + rosapi  {ws}{token}   (roslibjs, roslibpy, webviz)",
        f"  Foxglove WebSocket     {ws}{token}   (Foxglove, Lichtblick: 'Foxglove WebSocket')",
        f"  video                  {url}/streams{token}   (/stream?topic=..., /snapshot?topic=...)",
    ] + ([f"  wire trace             {url}/{token}#wire   (following {' '.join(settings.trace)})"]
         if settings.trace else []))


def asset_allowlist(value: Any) -> List[str]:
    """foxglove_bridge's ``~asset_uri_allowlist``: a list of regular expressions (one text is
    one expression); unset, :data:`minros.web.assets.DEFAULT_ALLOWLIST`."""
    from minros.web.assets import DEFAULT_ALLOWLIST

    if value is None:
        return list(DEFAULT_ALLOWLIST)
    if isinstance(value, str):
        return [value]
    return [str(v) for v in value]


def _origins(value: Any) -> List[str]:
    """``~allow_origin`` (one origin, a comma-separated text or a list) plus
    MINROS_WEB_ALLOW_ORIGIN."""
    import os

    from minros.web.origin import ENV_VAR, split_values

    given = [str(v) for v in value] if isinstance(value, list) else split_values(str(value or ""))
    return split_values(os.environ.get(ENV_VAR, "")) + given


def run_node(default_name: str, default_port: int, server_name: str, serve: bool = True) -> int:
    """Entry of the launch-file executables: settings from private parameters."""
    from minros.web.state import DEFAULT_UNREGISTER_TIMEOUT

    minros.init_node(default_name, disable_signals=True)

    def param(key: str, default: Any) -> Any:
        return minros.get_param("~" + key, default)

    max_size = param("max_message_size", None)
    allow = param("allow_origin", [])
    settings = Settings(
        host=str(param("address", "127.0.0.1") or "0.0.0.0"), port=int(param("port", default_port)),
        token=param("token", None) or None, name=default_name,
        topics_glob=parse_globs(param("topics_glob", "")),
        services_glob=parse_globs(param("services_glob", "")),
        params_glob=parse_globs(param("params_glob", "")),
        max_message_size=int(max_size) if str(max_size).isdigit() else 64 << 20,
        unregister_timeout=float(param("unregister_timeout", DEFAULT_UNREGISTER_TIMEOUT)),
        compression=bool(param("use_compression", False)), server_name=server_name,
        server=serve, allow_origins=_origins(allow), set_actual_port=serve)
    return run(settings, announce=minros.loginfo)
