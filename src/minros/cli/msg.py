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
import io
import os
import sys
from typing import Any, Callable, Iterator, List, Tuple

MODE_NAMES = {"msg": ("message type", "messages"), "srv": ("service type", "services")}


class _UsageFormatter(argparse.HelpFormatter):
    """Help that starts ``Usage:`` as rosmsg's (optparse) does: scripts look for it."""

    def add_usage(self, usage: Any, actions: Any, groups: Any, prefix: Any = None) -> None:
        super().add_usage(usage, actions, groups, "Usage: " if prefix is None else prefix)


def _parser(kind: str, prog: str) -> argparse.ArgumentParser:
    what, plural = MODE_NAMES[kind]
    parser = argparse.ArgumentParser(
        prog=prog, description=f"Display information about ROS {what}s.",
        formatter_class=_UsageFormatter)
    sub = parser.add_subparsers(dest="command", metavar="COMMAND",
                                parser_class=_subparser_class())
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


def _subparser_class() -> Any:
    class SubParser(argparse.ArgumentParser):
        def __init__(self, *args: Any, **kwds: Any) -> None:
            kwds.setdefault("formatter_class", _UsageFormatter)
            super().__init__(*args, **kwds)

    return SubParser


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
    if prog in ("rosmsg", "rossrv") and list(argv) in ([], ["-h"], ["--help"]):
        # ROS's command prints its own overview (the commands), which scripts look for
        print(fullusage(MODE_MSG if kind == "msg" else MODE_SRV))
        return 0
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


# ---------------------------------------------------------------------------------------------
# the Python API of ROS's rosmsg module (the stand-in re-exports it): the texts the command
# prints, the package searches, and rosmsg-proto's YAML prototypes of messages

MODE_MSG = ".msg"
MODE_SRV = ".srv"
#: a mapping or list with more items than this is written in block style by get_yaml_for_msg
MAX_DEFAULT_NON_FLOW_ITEMS = 4


class ROSMsgException(Exception):
    """A type could not be found or read."""


class RosMsgProtoException(Exception):
    """rosmsg-proto could not make a prototype (unknown or ambiguous type)."""


class RosMsgProtoArgsException(Exception):
    """rosmsg-proto was called with too few arguments."""


def _kind(mode: str) -> str:
    if mode not in (MODE_MSG, MODE_SRV):
        raise ValueError(f"Unknown mode: {mode}")
    return mode[1:]


def get_msg_text(type_: str, raw: bool = False, rospack: object = None) -> str:
    """What ``rosmsg show [-r] TYPE`` prints."""
    from minros.msgs.registry import UnknownTypeError, message_text

    try:
        return message_text(type_, raw)
    except (UnknownTypeError, ValueError) as exc:
        raise ROSMsgException(f"Unable to load msg [{type_}]: {exc}") from None


def get_srv_text(type_: str, raw: bool = False, rospack: object = None) -> str:
    """What ``rossrv show [-r] TYPE`` prints."""
    from minros.msgs.registry import UnknownTypeError, service_text

    try:
        return service_text(type_, raw)
    except (UnknownTypeError, ValueError) as exc:
        raise ROSMsgException(f"Unknown srv type [{type_}]: {exc}") from None


def spec_to_str(msg_context: Any, spec: Any, buff: Any = None, indent: str = "") -> str:
    """A genmsg spec as ``rosmsg show`` prints it: constants, then fields with the fields of
    embedded types indented below them (``msg_context.get_registered`` supplies those)."""
    from minros.msgs.loader import BUILTIN_TYPES, bare_msg_type

    out = buff if buff is not None else io.StringIO()
    for c in spec.constants:
        out.write(f"{indent}{c.type} {c.name}={c.val_text}\n")
    for type_, name in zip(spec.types, spec.names):
        out.write(f"{indent}{type_} {name}\n")
        base = bare_msg_type(type_)
        if base not in BUILTIN_TYPES:
            spec_to_str(msg_context, msg_context.get_registered(base), out, indent + "  ")
    return out.getvalue()


def rosmsg_debug(rospack: object, mode: str, type_: str, raw: bool = False) -> None:
    """Print the definition of ``type_`` (a message or service, by ``mode``)."""
    if mode == MODE_SRV:
        print(get_srv_text(type_, raw=raw, rospack=rospack))
    elif mode == MODE_MSG:
        print(get_msg_text(type_, raw=raw, rospack=rospack))
    else:
        raise ROSMsgException(f"Invalid mode for debug: {mode}")


def list_types(package: str, mode: str = MODE_MSG, rospack: object = None) -> List[str]:
    """``pkg/Type`` of the messages (or services) of ``package``, sorted."""
    import rospkg

    from minros.msgs.registry import UnknownTypeError
    from minros.msgs.registry import list_types as registry_list

    kind = _kind(mode)
    try:
        return registry_list(package, kind)
    except UnknownTypeError:
        raise rospkg.ResourceNotFound(package) from None


def list_msgs(package: str, rospack: object = None) -> List[str]:
    return list_types(package, MODE_MSG, rospack)


def list_srvs(package: str, rospack: object = None) -> List[str]:
    return list_types(package, MODE_SRV, rospack)


def iterate_packages(rospack: object, mode: str) -> Iterator[Tuple[str, str]]:
    """``(package, its msg or srv folder)`` of every package that has one: the packages
    ``rospack`` knows (a ``rospkg.RosPack``, as ROS's rosmsg takes), or without one minros's
    package lookup (ROS_PACKAGE_PATH, then the packages minros bundles)."""
    from minros.msgs.registry import packages_with

    kind = _kind(mode)
    if rospack is not None and hasattr(rospack, "list") and hasattr(rospack, "get_path"):
        for package in rospack.list():
            folder = os.path.join(rospack.get_path(package), kind)
            if os.path.isdir(folder):
                yield package, folder
        return
    for package, folder in packages_with(kind).items():
        yield package, str(folder)


def rosmsg_search(rospack: object, mode: str, base_type: str) -> Iterator[str]:
    """``pkg/Type`` of every package holding a type named ``base_type``."""
    yield from _matches(_kind(mode), base_type)


def rosmsg_md5(mode: str, type_: str) -> str:
    """The md5 sum of a message or service type (IOError when it cannot be loaded)."""
    from minros.msgs.registry import REGISTRY, UnknownTypeError

    try:
        return REGISTRY.md5sum(type_) if mode == MODE_MSG else REGISTRY.srv_md5sum(type_)
    except (UnknownTypeError, ValueError):
        raise OSError(f"cannot load [{type_}]") from None


def fullusage(mode: str) -> str:
    """rosmsg's (or rossrv's) usage text."""
    cmd = "ros" + mode[1:]
    what = "Message" if mode == MODE_MSG else "Service"
    low = what.lower()
    return (f"{cmd} is a command-line tool for displaying information about ROS {what} types.\n\n"
            f"Commands:\n"
            f"\t{cmd} show\tShow {low} description\n"
            f"\t{cmd} info\tAlias for {cmd} show\n"
            f"\t{cmd} list\tList all {low}s\n"
            f"\t{cmd} md5\tDisplay {low} md5sum\n"
            f"\t{cmd} package\tList {low}s in a package\n"
            f"\t{cmd} packages\tList packages that contain {low}s\n\n"
            f"Type {cmd} <command> -h for more detailed usage\n")


def _command(mode: str, command: str, args: List[str]) -> int:
    kind = _kind(mode)
    return main([command] + list(args), prog="ros" + kind, kind=kind)


def rosmsg_cmd_show(mode: str, full: str, alias: str = "show") -> int:
    """``rosmsg show`` with the arguments in sys.argv[2:]."""
    return _command(mode, alias, sys.argv[2:])


def rosmsg_cmd_md5(mode: str, full: str) -> int:
    return _command(mode, "md5", sys.argv[2:])


def rosmsg_cmd_package(mode: str, full: str) -> int:
    return _command(mode, "package", sys.argv[2:])


def rosmsg_cmd_packages(mode: str, full: str, argv: List[str] | None = None) -> int:
    return _command(mode, "packages", list(sys.argv[1:] if argv is None else argv)[1:])


def rosmsg_cmd_list(mode: str, full: str, argv: List[str] | None = None) -> int:
    return _command(mode, "list", list(sys.argv[1:] if argv is None else argv)[1:])


def rosmsgmain(mode: str = MODE_MSG) -> None:
    """The rosmsg (or, with MODE_SRV, rossrv) command on sys.argv."""
    kind = _kind(mode)
    sys.exit(main(sys.argv[1:], prog="ros" + kind, kind=kind))


# -- rosmsg-proto: a message as a YAML prototype (what shells complete ``rostopic pub`` with)

def construct_ordered_mapping(loader: Any, node: Any, deep: bool = False) -> Any:
    """A YAML mapping as an OrderedDict, keys in document order."""
    import collections

    import yaml

    if not isinstance(node, yaml.MappingNode):
        raise yaml.constructor.ConstructorError(
            None, None, f"expected a mapping node, but found {node.id}", node.start_mark)
    mapping = collections.OrderedDict()
    for key_node, value_node in node.value:
        key = loader.construct_object(key_node, deep=deep)
        try:
            hash(key)
        except TypeError:
            raise yaml.constructor.ConstructorError(
                "while constructing a mapping", node.start_mark, "found unhashable key",
                key_node.start_mark) from None
        mapping[key] = loader.construct_object(value_node, deep=deep)
    return mapping


def construct_yaml_map_with_ordered_dict(loader: Any, node: Any) -> Iterator[Any]:
    """PyYAML's two-step map constructor, making an OrderedDict."""
    import collections

    data: Any = collections.OrderedDict()
    yield data
    data.update(loader.construct_mapping(node))


def represent_ordered_mapping(dumper: Any, tag: str, mapping: Any, flow_style: Any = None) -> Any:
    """A mapping node with the items in their order (not sorted)."""
    import yaml

    value: List[Any] = []
    node = yaml.MappingNode(tag, value, flow_style=flow_style)
    if dumper.alias_key is not None:
        dumper.represented_objects[dumper.alias_key] = node
    best_style = True
    items = list(mapping.items()) if hasattr(mapping, "items") else list(mapping)
    for item_key, item_value in items:
        node_key = dumper.represent_data(item_key)
        node_value = dumper.represent_data(item_value)
        if not (isinstance(node_key, yaml.ScalarNode) and not node_key.style):
            best_style = False
        if not (isinstance(node_value, yaml.ScalarNode) and not node_value.style):
            best_style = False
        value.append((node_key, node_value))
    if flow_style is None:
        node.flow_style = dumper.default_flow_style if dumper.default_flow_style is not None else best_style
    return node


def init_rosmsg_proto() -> None:
    """What rosmsg-proto does first: make this process's PyYAML keep mappings in document
    order, loading and dumping (a change to PyYAML's classes, as ROS's rosmsg makes it)."""
    import collections

    import yaml

    yaml.constructor.BaseConstructor.construct_mapping = construct_ordered_mapping
    yaml.constructor.Constructor.add_constructor("tag:yaml.org,2002:map",
                                                 construct_yaml_map_with_ordered_dict)
    yaml.representer.BaseRepresenter.represent_mapping = represent_ordered_mapping
    yaml.representer.Representer.add_representer(collections.OrderedDict,
                                                 yaml.representer.SafeRepresenter.represent_dict)


def get_array_type_instance(field_type: str, default_package: str | None = None) -> Any:
    """One element of a field of type ``field_type`` (``float64[]`` -> 0, ``Header`` -> a
    std_msgs/Header), or None for a type that cannot be loaded."""
    from minros.msgs import get_message_class

    field_type = field_type.strip().rstrip("[]")
    if field_type == "empty":
        return None
    if "/" not in field_type:
        if field_type in ("byte", "int8", "int16", "int32", "int64", "char", "uint8", "uint16",
                          "uint32", "uint64", "float32", "float64"):
            return 0
        if field_type == "string":
            return ""
        if field_type == "bool":
            return False
        field_type = {"time": "std_msgs/Time", "duration": "std_msgs/Duration",
                      "Header": "std_msgs/Header"}.get(field_type, field_type)
        if "/" not in field_type:
            if default_package is None:
                return None
            field_type = f"{default_package}/{field_type}"
    try:
        return get_message_class(field_type)()
    except Exception:  # noqa: BLE001 - rosmsg answers None for any type it cannot load
        return None


def get_yaml_for_msg(msg: Any, prefix: str = "", time_offset: Any = None, current_time: Any = None,
                     field_filter: Callable | None = None, flow_style_: Any = None,
                     fill_arrays_: bool = False) -> str:
    """``msg`` (a message, dict or list) as YAML with fields in message order: flow style
    (one line) with ``flow_style_=True``, block style with False, and with None block style
    only for mappings and lists of more than 4 items; ``fill_arrays_`` puts one element in
    each empty variable-length array; every line starts with ``prefix``."""
    import collections

    import yaml

    from minros.msgs import Time

    class Dumper(yaml.SafeDumper):
        pass

    def represent_object(dumper: Any, obj: Any) -> Any:
        fields = list(field_filter(obj)) if field_filter is not None else list(obj.__slots__)
        slots = list(obj.__slots__)
        ndict: Any = collections.OrderedDict()
        for key in fields:
            if key.startswith("_"):
                continue
            val = getattr(obj, key)
            if isinstance(val, list) and len(val) > MAX_DEFAULT_NON_FLOW_ITEMS:
                dumper.default_flow_style = flow_style_
            if time_offset is not None and isinstance(val, Time):
                ndict[key] = val - time_offset
            elif fill_arrays_ and isinstance(val, list) and not val:
                slot_type = obj._slot_types[slots.index(key)] if key in slots else ""
                obj_type = getattr(obj, "_type", None)
                instance = None
                if obj_type and "/" in obj_type:
                    instance = get_array_type_instance(slot_type, obj_type.split("/")[0])
                ndict[key] = val if instance is None else [instance]
            elif not callable(val):
                ndict[key] = val
        if len(ndict) > MAX_DEFAULT_NON_FLOW_ITEMS:
            dumper.default_flow_style = flow_style_
        return represent_ordered_mapping(dumper, "tag:yaml.org,2002:map", ndict)

    Dumper.add_representer(None, represent_object)
    Dumper.add_representer(collections.OrderedDict,
                           lambda d, m: represent_ordered_mapping(d, "tag:yaml.org,2002:map", m))
    Dumper.add_representer(dict, lambda d, m: represent_ordered_mapping(d, "tag:yaml.org,2002:map", m))
    text = yaml.dump(msg, Dumper=Dumper, default_flow_style=flow_style_ is True, default_style="")
    if prefix:
        return prefix + ("\n" + prefix).join(text.splitlines())
    return text.rstrip("\n")


def create_names_filter(names: List[str]) -> Callable[[Any], List[str]]:
    """A field filter for get_yaml_for_msg leaving out the fields named in ``names``."""
    return lambda obj: [slot for slot in obj.__slots__ if slot not in names]


def rosmsg_cmd_prototype(args: List[str]) -> str | None:
    """rosmsg-proto: ``msg|srv TYPE [options]`` -> the YAML prototype of the message (of the
    service's request), quoted unless ``-H``; errors exit as rosmsg-proto exits."""
    import optparse
    import os

    from minros.msgs import UnknownTypeError, get_message_class, get_service_class

    parser = optparse.OptionParser(
        usage="usage: rosmsgproto msg/srv [options]",
        description="Produces output or a msg or service request, intended for tab completion support.")
    parser.add_option("-f", "--flow_style", dest="flow_style", type="int", default=None,
                      action="store", help="if 1 always use brackets, if 0 never use brackets. "
                                           "Default is a heuristic mix.")
    parser.add_option("-e", "--empty-arrays", dest="empty_arrays", default=False,
                      action="store_true", help="if true flexible size arrays are not filled with default instance")
    parser.add_option("-s", "--silent", dest="silent", default=False, action="store_true",
                      help="if true suppresses all error messages")
    parser.add_option("-p", "--prefix", metavar="prefix", default="",
                      help="prefix to print before each line, can be used for indent")
    parser.add_option("-H", "--no-hyphens", dest="no_hyphens", default="", action="store_true",
                      help="if true output has no outer hyphens")
    parser.add_option("-x", "--exclude-slots", metavar="exclude_slots", default="",
                      help="comma separated list of slot names not to print")
    options, args = parser.parse_args(args)
    usage_status = getattr(os, "EX_USAGE", 1)
    try:
        if len(args) < 2:
            raise RosMsgProtoArgsException("Insufficient arguments")
        mode, message_type = "." + args[0], args[1]
        field_filter = None
        if options.exclude_slots and options.exclude_slots.strip():
            field_filter = create_names_filter(options.exclude_slots.split(","))
        if "::" in message_type:
            if not options.silent:
                parser.error("rosmsgproto does not understand C++-style namespaces (i.e. '::').\n"
                             "Please refer to msg/srv types as 'package_name/Type'.")
        elif "." in message_type:
            if not options.silent:
                parser.error(f"invalid message type '{message_type}'.\n"
                             "Please refer to msg/srv types as 'package_name/Type'.")
        if mode not in (MODE_MSG, MODE_SRV):
            raise RosMsgProtoException(f"Invalid mode: {mode}")
        if "/" not in message_type:
            found = list(rosmsg_search(None, mode, message_type))
            if len(found) > 1:
                raise RosMsgProtoException(f"Ambiguous message name {message_type}")
            if not found:
                raise RosMsgProtoException(f"Unknown message name {message_type}")
            message_type = found[0]
        try:
            if mode == MODE_SRV:
                instance = get_service_class(message_type)._request_class()
            else:
                instance = get_message_class(message_type)()
        except (UnknownTypeError, LookupError):
            what = "service" if mode == MODE_SRV else "message"
            raise RosMsgProtoException(f"Unknown {what} class: {message_type}") from None
        text = get_yaml_for_msg(instance, prefix=options.prefix, flow_style_=options.flow_style,
                                fill_arrays_=not options.empty_arrays, field_filter=field_filter)
        return text if options.no_hyphens else f'"{text}"'
    except ValueError as exc:
        if not options.silent:
            sys.stderr.write(f"Invalid type: '{exc}'")
            sys.exit(usage_status)
    except RosMsgProtoException as exc:
        if not options.silent:
            sys.stderr.write(str(exc))
            sys.exit(1)
    except RosMsgProtoArgsException as exc:
        if not options.silent:
            sys.stderr.write(str(exc))
            sys.exit(usage_status)
    return None


if __name__ == "__main__":  # rosrun rosmsg rosmsg
    sys.exit(main(sys.argv[1:], prog="rosmsg"))
