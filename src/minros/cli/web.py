"""``minros web``: rosbridge v2 with rosapi, Foxglove WebSocket and video endpoints on one port.

``minros web [--port 9090] [--host 127.0.0.1] [--token TOKEN] [--allow-origin ORIGIN]
[--trace PATH...] [--learn-dir DIR] ...`` runs until Ctrl-C as the node ``/minros_web``
(``__name:=`` renames it); ``--allow-origin`` (or MINROS_WEB_ALLOW_ORIGIN) lets pages of another
site use the server; ``--trace`` names the wire traces (``minros trace -o FILE -- COMMAND``) the
page's Wire view follows; ``--learn-dir`` the folder the Learn view's exercises run in (as
``minros learn --dir``). roslaunch users
start the same server with ``roslaunch rosbridge_server rosbridge_websocket.launch`` or
``roslaunch foxglove_bridge foxglove_bridge.launch``.
"""

from __future__ import annotations

import argparse
import sys
from typing import List


def _parser(prog: str) -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(
        prog=prog,
        description="Serve the ROS graph to browsers and GUIs on one port: a page at / to see "
                    "and drive it (graph, topics, plots, images, a 3D view as Rviz's, turtlesim, "
                    "parameters, services, console, the wire trace, and Learn: minros learn's "
                    "exercises started, watched and checked), rosbridge v2 with rosapi (roslibjs, roslibpy, "
                    "webviz), the Foxglove WebSocket protocol (Foxglove, Lichtblick) and web_video_server's "
                    "/stream, /snapshot and /stream_viewer endpoints.")
    parser.add_argument("--port", type=int, default=9090, help="TCP port (default 9090)")
    parser.add_argument("--host", default="127.0.0.1",
                        help="address to listen on (default 127.0.0.1: this machine only; "
                             "0.0.0.0 for every interface)")
    parser.add_argument("--token", help="a secret every client must present, as ?token=... in "
                                        "the URL or an 'Authorization: Bearer' header")
    parser.add_argument("--allow-origin", action="append", default=[], metavar="ORIGIN",
                        help="let pages of ORIGIN (scheme://host[:port], e.g. "
                             "https://app.foxglove.dev for a Foxglove, Lichtblick or webviz app "
                             "hosted there) use the server; repeatable, and added to the "
                             "comma-separated list of $MINROS_WEB_ALLOW_ORIGIN. By default only "
                             "the server's own pages and pages on localhost may (clients that "
                             "are not web pages always may). 'null' allows file:// pages, '*' "
                             "any page: then any web site you visit can drive your robot")
    parser.add_argument("--name", default="minros_web", help="node name (default minros_web)")
    parser.add_argument("--topics-glob", default="", metavar="GLOBS",
                        help="only these topics, e.g. '[/turtle1/*, /rosout]' (default: all)")
    parser.add_argument("--services-glob", default="", metavar="GLOBS",
                        help="only these services (default: all)")
    parser.add_argument("--params-glob", default="", metavar="GLOBS",
                        help="only these parameters (default: all)")
    parser.add_argument("--max-message-size", type=int, default=64 << 20, metavar="BYTES",
                        help="largest message a client may send (default 64 MiB); larger ones "
                             "close that client's connection")
    parser.add_argument("--send-timeout", type=float, default=10.0, metavar="SECONDS",
                        help="close a client that reads nothing for this long while data waits "
                             "(default 10)")
    parser.add_argument("--graph-interval", type=float, default=1.0, metavar="SECONDS",
                        help="how often the graph is read from a master that cannot push its "
                             "changes, such as rosmaster (default 1; minros's master pushes)")
    parser.add_argument("--compression", action="store_true",
                        help="offer permessage-deflate (costs CPU on images)")
    parser.add_argument("--trace", nargs="+", action="extend", default=[], metavar="PATH",
                        help="follow these wire traces live in the page's Wire view: files "
                             "written by 'minros trace -o FILE -- COMMAND' or MINROS_TRACE=FILE "
                             "(they may not exist yet), directories (their *.jsonl) or quoted "
                             "glob patterns")
    parser.add_argument("--learn-dir", metavar="DIR",
                        help="the folder the Learn view's exercises run in, one folder each "
                             "(default $MINROS_LEARN_DIR, else $ROS_HOME/learn, i.e. "
                             "~/.ros/learn; 'minros learn --dir' names the same)")
    return parser


def main(argv: List[str], prog: str | None = None) -> int:
    import os

    from minros.tools.common import strip_ros_args
    from minros.web.node import Settings, parse_globs, run
    from minros.web.origin import ENV_VAR, OriginError, normalize, split_values

    name = prog or "minros web"
    args = _parser(name).parse_args(strip_ros_args(list(argv)))
    if not 0 <= args.port <= 65535:
        print(f"{name}: error: --port {args.port} is not a TCP port (0-65535)", file=sys.stderr)
        return 2
    origins = split_values(os.environ.get(ENV_VAR, "")) + args.allow_origin
    try:
        for origin in origins:
            normalize(origin)
    except OriginError as exc:
        print(f"{name}: error: {exc}", file=sys.stderr)
        return 2
    settings = Settings(host=args.host, port=args.port, token=args.token, name=args.name,
                        topics_glob=parse_globs(args.topics_glob),
                        services_glob=parse_globs(args.services_glob),
                        params_glob=parse_globs(args.params_glob),
                        graph_interval=max(0.05, args.graph_interval),
                        send_timeout=max(0.5, args.send_timeout),
                        max_message_size=args.max_message_size, compression=args.compression,
                        trace=args.trace, allow_origins=origins,
                        learn_dir=os.path.expanduser(args.learn_dir) if args.learn_dir else None)
    return run(settings, announce=lambda text: print(text, flush=True))
