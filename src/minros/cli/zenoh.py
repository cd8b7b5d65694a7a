"""``minros zenoh``: bridge the master of ROS_MASTER_URI with a Zenoh network.

    minros zenoh [--listen tcp/0.0.0.0:7447] [--connect tcp/10.0.0.5:7447 ...]
                 [--no-multicast-scouting] [--namespace NS] [--mode peer|client]
    minros zenoh keys /chatter [--type std_msgs/String] [--namespace NS] [--all]

Wire-compatible with zenoh-bridge-ros1: two masters whose bridges share only a Zenoh link
see each other's topics and services, whichever bridge each runs. The bridge needs the
``eclipse-zenoh`` package (``pip install minros[zenoh]``); ``keys`` does not.
"""

from __future__ import annotations

import argparse
import sys
from typing import List, Optional, Tuple

from minros.tools.common import strip_ros_args


def _bridge_parser(prog: str) -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(
        prog=prog,
        description="Bridge the topics and services of the ROS master at ROS_MASTER_URI with a "
                    "Zenoh network, compatible with zenoh-bridge-ros1: a talker behind one "
                    "bridge is heard by a listener behind another, a service behind one is "
                    "called from behind another. minros bridges also carry message "
                    "definitions and latching to each other. 'minros zenoh keys NAME' prints "
                    "the Zenoh key expression of a topic or service.",
        epilog="Without --listen or --connect, peers find each other by UDP multicast on the "
               "local network. Zenoh's own log: RUST_LOG=info.")
    parser.add_argument("--listen", action="append", default=[], metavar="ENDPOINT",
                        help="accept Zenoh connections on ENDPOINT, e.g. tcp/0.0.0.0:7447 "
                             "(repeatable)")
    parser.add_argument("--connect", action="append", default=[], metavar="ENDPOINT",
                        help="connect to a Zenoh peer or router at ENDPOINT, e.g. "
                             "tcp/10.0.0.5:7447 (repeatable)")
    parser.add_argument("--no-multicast-scouting", action="store_true",
                        help="do not look for peers by UDP multicast (networks that block it, "
                             "or when --connect names them all)")
    parser.add_argument("--namespace", default="*", metavar="NS",
                        help="bridge namespace, zenoh-bridge-ros1's BRIDGE_NAMESPACE: one word; "
                             "bridges of one namespace see each other and those of '*' "
                             "(default '*': every namespace)")
    parser.add_argument("--mode", choices=("peer", "client"), default="peer",
                        help="Zenoh mode: peer (default; no router needed) or client (through "
                             "the router or peer named by --connect)")
    parser.add_argument("--service-timeout", type=float, default=10.0, metavar="SECONDS",
                        help="how long a call of a remote service may take (default 10)")
    parser.add_argument("--max-remote", type=int, default=1000, metavar="N",
                        help="bridge at most N topics and services that only remote beacons "
                             "declare (no local node publishes, subscribes or serves them; the "
                             "first heard are kept; default 1000): a peer cannot make this "
                             "master and process grow without bound")
    parser.add_argument("--name", default="minros_zenoh", help="node name (default minros_zenoh)")
    return parser


def _keys_parser(prog: str) -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(
        prog=prog,
        description="Print the Zenoh key expression under which zenoh-bridge-ros1 and minros "
                    "zenoh carry a topic's messages (or a service's calls): "
                    "<hex of the type>/<md5sum>/<bridge namespace>/<name>. The type comes from "
                    "--type or from the master.")
    parser.add_argument("name", help="topic or service name, e.g. /chatter")
    parser.add_argument("--type", metavar="TYPE",
                        help="message or service type, e.g. std_msgs/String (default: ask the "
                             "master and the publisher)")
    parser.add_argument("--namespace", default="*", metavar="NS", help="bridge namespace (default *)")
    parser.add_argument("--all", action="store_true",
                        help="also print the discovery keys of the beacons that declare it")
    return parser


def main(argv: List[str], prog: Optional[str] = None) -> int:
    prog = prog or "minros zenoh"
    argv = strip_ros_args(list(argv))
    if argv and argv[0] == "keys":
        return _keys(_keys_parser(f"{prog} keys").parse_args(argv[1:]))
    args = _bridge_parser(prog).parse_args(argv)
    from minros import zenoh as extra

    if not extra.available():
        print(f"{prog}: error: {extra.MISSING_EXTRA}", file=sys.stderr)
        return 1
    if args.service_timeout <= 0:
        print(f"{prog}: error: --service-timeout must be positive", file=sys.stderr)
        return 2
    if args.max_remote < 0:
        print(f"{prog}: error: --max-remote must be 0 or more", file=sys.stderr)
        return 2
    from minros.zenoh.bridge import Options, run
    from minros.zenoh.keys import KeyMappingError, check_namespace

    try:
        check_namespace(args.namespace)
    except KeyMappingError as exc:
        print(f"{prog}: error: {exc}", file=sys.stderr)
        return 2
    options = Options(mode=args.mode, listen=args.listen, connect=args.connect,
                      multicast_scouting=not args.no_multicast_scouting,
                      namespace=args.namespace, service_timeout=args.service_timeout,
                      max_remote=args.max_remote)
    return run(options, name=args.name, announce=lambda text: print(text, flush=True))


# -- keys ---------------------------------------------------------------------------------------


class _NotFound(Exception):
    pass


def _installed(type_name: str) -> Tuple[str, str]:
    """(kind, md5sum) of an installed message ("pub") or service ("srv") type."""
    from minros.msgs import get_message_class, get_service_class

    for kind, get in (("pub", get_message_class), ("srv", get_service_class)):
        try:
            return kind, get(type_name)._md5sum
        except Exception:  # noqa: BLE001 - not that kind
            continue
    raise _NotFound(f"type {type_name} is not installed here: its md5sum is unknown "
                    "(run without --type to ask the publisher)")


def _from_master(name: str) -> Tuple[str, str, str]:
    """(kind, type, md5sum) of ``name`` from the master and the node that offers it."""
    from minros.tools.master import Master, MasterException
    from minros.tools.services import probe_service
    from minros.zenoh.graph import probe_publisher

    master = Master("/minros_zenoh_keys")
    try:
        types = dict(master.topic_types())
        pubs, _subs, srvs = master.system_state()
        if name in types:
            nodes = next((n for t, n in pubs if t == name), [])
            for node in nodes:
                try:
                    header = probe_publisher(master.lookupNode(node), name, master.caller_id)
                    return "pub", header["type"], header["md5sum"]
                except (OSError, KeyError, MasterException):
                    continue
            kind, md5 = _installed(types[name])
            return "pub", types[name], md5
        if any(s == name for s, _n in srvs):
            header = probe_service(master.lookupService(name), name, master.caller_id)
            return "srv", header["type"], header["md5sum"]
    finally:
        master.close()
    raise _NotFound(f"{name} is neither a topic nor a service of the master at {master.uri} "
                    "(give its type with --type)")


def _keys(args: argparse.Namespace) -> int:
    from minros.tools.common import resolve
    from minros.tools.master import MasterIOError
    from minros.zenoh.keys import KeyMappingError, data_key, discovery_key

    name = resolve("minros_zenoh", args.name)
    try:
        if args.type:
            kind, md5 = _installed(args.type)
            type_name = args.type
        else:
            kind, type_name, md5 = _from_master(name)
        print(data_key(name, type_name, md5, args.namespace))
        if args.all:
            for cls in (("pub", "sub") if kind == "pub" else ("srv", "cl")):
                print(discovery_key(cls, name, type_name, md5, args.namespace))
    except (_NotFound, KeyMappingError) as exc:
        print(f"ERROR: {exc}", file=sys.stderr)
        return 1
    except (MasterIOError, OSError) as exc:
        print(f"ERROR: cannot ask the master about {name}: {exc} (give its type with --type)",
              file=sys.stderr)
        return 1
    return 0
