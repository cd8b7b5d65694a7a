"""``minros msg`` (rosmsg): show, hash, list and generate message types.

    minros msg show [-r] TYPE     expanded definition (-r: raw file text with comments)
    minros msg md5 TYPE           md5 sum
    minros msg gen [--numpy] TYPE the Python source minros generates for the class
    minros msg list               every message type
    minros msg package PKG        the message types of a package
    minros msg packages           packages that contain messages

A TYPE without a package (``Header``, ``String``) is searched in every package, as rosmsg
does; with no TYPE argument, it is read from stdin (``rostopic type /chatter | rosmsg show``).
``minros srv`` (rossrv) is the same tool for services (no ``gen``).
"""

from __future__ import annotations

import argparse
import sys
from typing import Callable, List

MODE_NAMES = {"msg": ("message type", "messages"), "srv": ("service type", "services")}


def _parser(kind: str, prog: str) -> argparse.ArgumentParser:
    what, plural = MODE_NAMES[kind]
    parser = argparse.ArgumentParser(
        prog=prog, description=f"Display information about ROS {what}s.")
    sub = parser.add_subparsers(dest="command", metavar="COMMAND")
    for name in ("show", "info"):
        p = sub.add_parser(name, help=f"show {what} description" if name == "show"
                           else "alias for show")
        p.add_argument("-r", "--raw", action="store_true",
                       help=f"show raw {'message' if kind == 'msg' else 'service'} text, including comments")
        if kind == "msg":
            p.add_argument("-b", "--bag", metavar="BAGFILE", help="show message from .bag file")
        p.add_argument("type", nargs="?", help=f"{what} (pkg/Type, or Type to search)")
    p = sub.add_parser("md5", help=f"display {what} md5sum")
    p.add_argument("type", nargs="?", help=what)
    if kind == "msg":
        p = sub.add_parser("gen", help="print the Python source generated for a message class")
        p.add_argument("--numpy", action="store_true", help="the numpy_msg variant")
        p.add_argument("type", nargs="?", help=what)
    sub.add_parser("list", help=f"list all {plural}")
    p = sub.add_parser("package", help=f"list {plural} in a package")
    p.add_argument("-s", dest="single_line", action="store_true",
                   help=f"list all {plural} on a single line")
    p.add_argument("package", nargs="?")
    p = sub.add_parser("packages", help=f"list packages that contain {plural}")
    p.add_argument("-s", dest="single_line", action="store_true",
                   help="list all packages on a single line")
    return parser


def _read_stdin_arg() -> str | None:
    for line in sys.stdin:
        if line.strip():
            return line.strip()
    return None


def _matches(kind: str, base_type: str) -> List[str]:
    from minros.msgs.registry import packages_with

    return [f"{pkg}/{base_type}" for pkg, folder in packages_with(kind).items()
            if (folder / f"{base_type}.{kind}").is_file()]


def main(argv: List[str], prog: str = "minros msg", kind: str = "msg") -> int:
    """Run ``minros msg`` (or, with ``kind='srv'``, ``minros srv``)."""
    parser = _parser(kind, prog)
    args = parser.parse_args(argv)
    if args.command is None:
        parser.print_help()
        return 0
    try:
        return _run(args, kind, prog, parser)
    except Exception as exc:  # noqa: BLE001 - expected failures become one line
        from minros.msgs import MsgSpecError, UnknownTypeError

        if isinstance(exc, (UnknownTypeError, MsgSpecError)):
            print(f"{prog}: {exc}", file=sys.stderr)
            return 1
        raise


def _run(args: argparse.Namespace, kind: str, prog: str, parser: argparse.ArgumentParser) -> int:
    from minros.msgs import registry

    command = args.command
    what = MODE_NAMES[kind][0]
    if command in ("show", "info", "md5", "gen"):
        type_name = args.type or _read_stdin_arg()
        if not type_name:
            parser.error(f"you must specify a {what}")
        if type_name.endswith("." + kind):
            type_name = type_name[:-len(kind) - 1]
        if "::" in type_name or "." in type_name:
            print(f"{prog}: invalid {what} '{type_name}': refer to types as 'package_name/Type'",
                  file=sys.stderr)
            return 2
        if command in ("show", "info") and getattr(args, "bag", None):
            return _show_from_bag(args.bag, type_name, args.raw, prog)
        show: Callable[[str], str]
        if command in ("show", "info"):
            text_of = registry.message_text if kind == "msg" else registry.service_text

            def show(t: str) -> str:
                return text_of(t, raw=args.raw)
        elif command == "md5":
            def show(t: str) -> str:
                if kind == "msg":
                    return registry.REGISTRY.md5sum(t)
                return registry.REGISTRY.srv_md5sum(t)
        else:
            def show(t: str) -> str:
                return registry.REGISTRY.source(t, numpy=args.numpy)
        if "/" in type_name:
            text = _describe(show, type_name, kind, command)
            if text is None:
                return 1
            print(text)
            return 0
        found = _matches(kind, type_name)
        if not found:
            print(f"Could not find {kind} '{type_name}'", file=sys.stderr)
            return 1
        status = 0
        for full in found:
            text = _describe(show, full, kind, command)
            if text is None:
                status = 1
                continue
            if command == "md5":
                print(f"[{full}]: {text}")
            else:
                print(f"[{full}]:")
                print(text)
        return status
    if command == "list":
        for pkg in registry.packages_with(kind):
            for name in registry.list_types(pkg, kind):
                print(name)
        return 0
    if command == "package":
        package = args.package or _read_stdin_arg()
        if not package:
            parser.error("you must specify a package")
        names = registry.list_types(package, kind)
        print((" " if args.single_line else "\n").join(names))
        return 0
    if command == "packages":
        print((" " if args.single_line else "\n").join(registry.packages_with(kind)))
        return 0
    parser.error(f"unknown command {command}")
    return 2


def _show_from_bag(path: str, type_name: str, raw: bool, prog: str) -> int:
    """rosmsg show -b: the definition of ``type_name`` as the bag stores it."""
    import os

    from minros.bag import Bag, ROSBagException

    if not os.path.exists(path):
        print(f"ERROR: bag file [{path}] does not exist", file=sys.stderr)
        return 1
    try:
        with Bag(path) as bag:
            conn = next((c for c in bag._connections.values() if c.datatype == type_name), None)
    except ROSBagException as exc:
        print(f"{prog}: ERROR reading {path}: {exc}", file=sys.stderr)
        return 1
    if conn is None:
        return 0  # rosmsg prints nothing for a type the bag does not hold
    if raw:
        print(conn.msg_def)
        return 0
    from minros.msgs import generate_dynamic
    from minros.msgs.registry import spec_to_text

    cls = generate_dynamic(type_name, conn.msg_def)[type_name]
    print(spec_to_text(cls._context.get_spec(type_name), cls._context))
    return 0


def _describe(show: Callable[[str], str], type_name: str, kind: str, command: str) -> str | None:
    from minros.msgs import UnknownTypeError

    try:
        return show(type_name)
    except UnknownTypeError as exc:
        if command == "md5":
            print(f"Cannot locate [{type_name}]: {exc}", file=sys.stderr)
        elif kind == "srv":
            print(f"Unknown srv type [{type_name}]: {exc}", file=sys.stderr)
        else:
            print(f"Unable to load msg [{type_name}]: {exc}", file=sys.stderr)
        return None


if __name__ == "__main__":  # rosrun rosmsg rosmsg
    sys.exit(main(sys.argv[1:], prog="rosmsg"))
