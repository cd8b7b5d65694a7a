"""``minros topic`` / ``rostopic``: list, info, type, find, echo, pub, hz, bw and delay.

Texts and exit statuses follow Debian's rostopic (ros_comm 1.15). ``echo``, ``hz`` and ``bw``
subscribe with md5 ``*`` and decode with the publisher's definition, so they work for types
that are not installed locally.

The sub-commands live in modules of their own: ``echo`` (and ``list -b``) in
:mod:`.topic_echo`, ``hz``/``bw``/``delay`` in :mod:`.topic_rates`, ``pub`` in
:mod:`.topic_pub`, what they share in :mod:`.topic_common`; rostopic's Python API is
:mod:`.topic_api`.
"""

from __future__ import annotations

import argparse
import sys
from typing import Dict, List
from urllib.parse import urlparse

from minros import names
from minros.cli.topic_common import (
    NAME,
    get_topic_list,
    info_text,
    master_client,
    message_class,
    topic_type,
)
from minros.cli.topic_echo import echo_cmd, list_bag
from minros.cli.topic_pub import pub_cmd
from minros.cli.topic_rates import bw_cmd, delay_cmd, hz_cmd
from minros.tools.common import dispatch, option_parser, resolve, run_tool
from minros.tools.master import Master

USAGE = """rostopic is a command-line tool for printing information about ROS Topics.

Commands:
\trostopic bw\tdisplay bandwidth used by topic
\trostopic delay\tdisplay delay of topic from timestamp in header
\trostopic echo\tprint messages to screen
\trostopic find\tfind topics by type
\trostopic hz\tdisplay publishing rate of topic\x20\x20\x20\x20
\trostopic info\tprint information about active topic
\trostopic list\tlist active topics
\trostopic pub\tpublish data to topic
\trostopic type\tprint topic or field type

Type rostopic <command> -h for more detailed usage, e.g. 'rostopic echo -h'
"""


def _print_list(master: Master, pubs: list, subs: list, pubs_only: bool, subs_only: bool,
                verbose: bool, indent: str = "") -> None:
    if verbose:
        if not subs_only:
            print(f"\n{indent}Published topics:")
            for t, ty, nodes in pubs:
                if len(nodes) > 1:
                    print(f"{indent} * {t} [{ty}] {len(nodes)} publishers")
                else:
                    print(f"{indent} * {t} [{ty}] 1 publisher")
        if not pubs_only:
            print(indent)
            print(f"{indent}Subscribed topics:")
            for t, ty, nodes in subs:
                if len(nodes) > 1:
                    print(f"{indent} * {t} [{ty}] {len(nodes)} subscribers")
                else:
                    print(f"{indent} * {t} [{ty}] 1 subscriber")
        print("")
        return
    if pubs_only:
        topics = [t for t, _, _ in pubs]
    elif subs_only:
        topics = [t for t, _, _ in subs]
    else:
        topics = list({t for t, _, _ in pubs} | {t for t, _, _ in subs})
    print("\n".join(f"{indent}{t}" for t in sorted(topics)))


def _cmd_list(argv: List[str], prog: str) -> int:
    p = option_parser(prog, " [/namespace]")
    p.add_option("-b", "--bag", dest="bag", default=None, metavar="BAGFILE", help="list topics in .bag file")
    p.add_option("-v", "--verbose", dest="verbose", default=False, action="store_true",
                 help="list full details about each topic")
    p.add_option("-p", dest="publishers", default=False, action="store_true", help="list only publishers")
    p.add_option("-s", dest="subscribers", default=False, action="store_true", help="list only subscribers")
    p.add_option("--host", dest="hostname", default=False, action="store_true", help="group by host name")
    args, namespace = p.parse_args(argv)
    args.namespace = namespace
    if len(args.namespace) > 1:
        p.error("you may only specify one input topic")
    if args.bag:
        # the usage errors rostopic gives with a bag come first
        for flag, given in (("-s", args.subscribers), ("-p", args.publishers), ("--host", args.hostname)):
            if given:
                p.error(f"{flag} option is not valid with bags")
        return list_bag(args.bag, resolve(NAME, args.namespace[0]) if args.namespace else None)
    if args.publishers and args.subscribers:
        p.error("you may only specify one of -p, -s")
    master = master_client()
    pubs, subs = get_topic_list(master)
    if args.namespace:
        topic = resolve(NAME, args.namespace[0])
        ns = names.make_global_ns(topic)
        pubs = [x for x in pubs if x[0] == topic or x[0].startswith(ns)]
        subs = [x for x in subs if x[0] == topic or x[0].startswith(ns)]
    if not args.hostname:
        _print_list(master, pubs, subs, args.publishers, args.subscribers, args.verbose)
        return 0
    uris: Dict[str, str | None] = {}

    def by_host(entries: list) -> Dict[str, list]:
        out: Dict[str, list] = {}
        for t, ty, nodes in entries:
            for n in nodes:
                uri = master.lookup_node_cached(uris, n)
                host = urlparse(uri).hostname if uri else None
                rows = out.setdefault(str(host), [])
                match = [row for row in rows if row[0] == t]
                if match:
                    match[0][2].append(n)
                else:
                    rows.append((t, ty, [n]))
        return out

    host_pubs, host_subs = by_host(pubs), by_host(subs)
    for host in sorted(set(host_pubs) | set(host_subs)):
        hp, hs = host_pubs.get(host, []), host_subs.get(host, [])
        if (hp and not args.subscribers) or (hs and not args.publishers):
            print(f"Host [{host}]:")
            _print_list(master, hp, hs, args.publishers, args.subscribers, args.verbose, indent="  ")
    return 0


def _one_topic(argv: List[str], prog: str, missing: str = "topic must be specified",
               many: str = "you may only specify one input topic") -> str:
    p = option_parser(prog, " /topic")
    _options, topics = p.parse_args(argv)
    if not topics:
        p.error(missing)
    if len(topics) > 1:
        p.error(many)
    return resolve(NAME, topics[0])


def _cmd_info(argv: List[str], prog: str) -> int:
    topic = _one_topic(argv, prog, "you must specify a topic name", "you may only specify one topic name")
    print(info_text(master_client(), topic))
    return 0


def _cmd_type(argv: List[str], prog: str) -> int:
    # rostopic parses 'type' with argparse (its usage and errors name "rostopic type")
    p = argparse.ArgumentParser(prog=prog)
    p.add_argument("topic_or_field", help="Topic or field name")
    args = p.parse_args(argv)
    topic = resolve(NAME, args.topic_or_field)
    type_name, real, _field = topic_type(master_client(), topic)
    if type_name is None:
        sys.stderr.write(f"unknown topic type [{topic}]\n")
        return 1
    if topic == real:
        print(type_name)
        return 0
    from minros.tools.echo import field_type

    field = topic[len(real) + 1:]
    cls = message_class(type_name)
    ftype = field_type(cls, field) if cls is not None else None
    if ftype is None:
        sys.stderr.write(f"unknown topic type [{topic}]\n")
        return 1
    print(f"{type_name} {field} {ftype}")
    return 0


def _cmd_find(argv: List[str], prog: str) -> int:
    p = option_parser(prog, " msg-type")
    _options, types = p.parse_args(argv)
    if not types:
        p.error("please specify a message type")
    if len(types) > 1:
        p.error("you may only specify one message type")
    print("\n".join(t for t, ty in master_client().topic_types() if ty == types[0]))
    return 0


COMMANDS = {"list": _cmd_list, "info": _cmd_info, "type": _cmd_type, "find": _cmd_find,
            "echo": echo_cmd, "pub": pub_cmd, "hz": hz_cmd, "bw": bw_cmd, "delay": delay_cmd}


def main(argv: List[str], prog: str = "rostopic") -> int:
    if argv[:1] in (["-h"], ["--help"]):
        # rostopic has no -h of its own: like any unknown command, the usage and EX_USAGE
        print(USAGE)
        return 64
    return run_tool(lambda: dispatch(argv, prog, COMMANDS, USAGE, usage_status=64))


if __name__ == "__main__":  # rosrun rostopic rostopic / <node pkg="rostopic" type="rostopic">
    sys.exit(main(sys.argv[1:]))
