"""``rosrun dynamic_reconfigure dynparam``: list, get, set, dump and load node configurations.

Same commands, options, texts and exit statuses as ROS 1's dynparam. Where ROS prints a
traceback for an expected failure (a timeout in ``get``, a failing server callback), this
prints one line and exits 1. Dump files are ROS's (YAML with the Config type's tag); ``load``
reads them without constructing arbitrary Python objects.
"""

from __future__ import annotations

import optparse
import sys
from typing import Any, Callable, Dict, List

import yaml

import minros

NAME = "dynparam"

USAGE = """dynparam is a command-line tool for getting, setting, and
deleting parameters of a dynamically configurable node.

Commands:
\tdynparam set                  configure node
\tdynparam set_from_parameters  copy configuration from parameter server
\tdynparam get                  get node configuration
\tdynparam load                 load configuration from file
\tdynparam dump                 dump configuration to file
\tdynparam list                 list configurable nodes

Type dynparam <command> -h for more detailed usage, e.g. 'dynparam get -h'
"""

SET_FROM_PARAMETERS_USAGE = """Usage: %prog set_from_parameters [options] node

Example command line:
  dynparam set_from_parameters wge100_camera _camera_url:=foo

Example launch file:
  <launch>
    <node name="$(anon adjust-wge100_camera)" pkg="dynamic_reconfigure" type="dynparam" args="set_from_parameters wge100_camera">
      <param name="camera_url" value="foo" />
      <param name="brightness" value="58" />
    </node>
  </launch>"""

SET_USAGE = """Usage: %prog set [options] node parameter value
   or: %prog set [options] node values

Examples:
  dynparam set wge100_camera camera_url foo
  dynparam set wge100_camera "{'camera_url':'foo', 'brightness':58}" """

_SET_ARGS_ERROR = ("invalid arguments. Please specify either a node name, parameter name and "
                   "parameter value, or a node name and a YAML dictionary")


class _Failed(Exception):
    """An expected failure: one line on stdout, exit status 1."""


def _parser(usage: str) -> optparse.OptionParser:
    parser = optparse.OptionParser(usage=usage, prog=NAME)
    parser.add_option("-t", "--timeout", action="store", type="float", default=None,
                      help="timeout in secs")
    return parser


def _node_arg(parser: optparse.OptionParser, args: List[str], second: str | None = None) -> List[str]:
    """Check the positional arguments of get/load/dump/set_from_parameters."""
    wanted = 1 if second is None else 2
    if not args:
        parser.error("invalid arguments. Please specify a node name")
    if len(args) < wanted:
        parser.error(f"invalid arguments. Please specify {second}")
    if len(args) > wanted:
        parser.error("too many arguments")
    return args


def connect() -> None:
    minros.init_node("dynparam", anonymous=True)


def _client(node: str, timeout: float | None) -> Any:
    from .client import Client

    return Client(node, timeout=timeout)


def get_params(node: str, timeout: float | None = None) -> Any:
    return _client(node, timeout).get_configuration(timeout=timeout)


def set_params(node: str, params: Dict[str, Any], timeout: float | None = None) -> None:
    from . import DynamicReconfigureCallbackException, DynamicReconfigureParameterException

    client = _client(node, timeout)
    try:
        client.update_configuration(params)
    except DynamicReconfigureParameterException as exc:
        print(f"error updating parameters: {exc}")
    except DynamicReconfigureCallbackException as exc:
        raise _Failed(f"couldn't set parameters at node {node}: {exc}") from None


def do_list(argv: List[str]) -> int:
    from . import find_reconfigure_services

    for name in find_reconfigure_services():
        print(name)
    return 0


def do_set_from_parameters(argv: List[str]) -> int:
    parser = _parser(SET_FROM_PARAMETERS_USAGE)
    options, args = parser.parse_args(argv)
    node = _node_arg(parser, args)[0]
    connect()
    try:
        params = minros.get_param("~")
    except KeyError:
        print("error updating parameters: no parameters found on parameter server", file=sys.stderr)
        return 0
    set_params(node, params, timeout=options.timeout)
    return 0


def do_set(argv: List[str]) -> int:
    # a negative number is a value, not an option
    args = [a for a in argv if not a.startswith("-") or (len(a) > 1 and a[1].isdigit())]
    option_args = [a for a in argv if a not in args]
    parser = _parser(SET_USAGE)
    options, _ = parser.parse_args(option_args)
    if len(args) > 3:
        parser.error("too many arguments")
    if len(args) < 2:
        parser.error(_SET_ARGS_ERROR)
    node = args[0]
    if len(args) == 2:
        try:
            values = yaml.safe_load(args[1])
        except yaml.YAMLError:
            values = None
        if type(values) is not dict:
            parser.error(_SET_ARGS_ERROR)
    else:
        values = {args[1]: args[2]}
    connect()
    try:
        set_params(node, values, timeout=options.timeout)
    except (minros.ServiceException, minros.ROSException):
        print(f"couldn't set parameters at node {node}")
    return 0


def do_get(argv: List[str]) -> int:
    parser = _parser("Usage: %prog get [options] node")
    options, args = parser.parse_args(argv)
    node = _node_arg(parser, args)[0]
    connect()
    params = _get_or_fail(node, options.timeout)
    if params is not None:
        print(params)
    return 0


def _get_or_fail(node: str, timeout: float | None) -> Any:
    try:
        return get_params(node, timeout=timeout)
    except minros.ROSException as exc:
        raise _Failed(f"couldn't get parameters from node {node}: {exc}") from None


def do_load(argv: List[str]) -> int:
    parser = _parser("Usage: %prog load [options] node file")
    options, args = parser.parse_args(argv)
    node, path = _node_arg(parser, args, "an input file")
    try:
        with open(path) as f:
            text = f.read()
    except OSError as exc:
        raise _Failed(f"cannot read {path}: {exc.strerror}") from None
    params: Dict[str, Any] = {}
    try:
        for doc in yaml.load_all(text, Loader=DumpLoader):
            if doc is not None:
                params.update(doc)
    except (yaml.YAMLError, TypeError, ValueError) as exc:
        raise _Failed(f"{path} is not a dynparam dump (YAML mappings): "
                      f"{' '.join(str(exc).split())}") from None
    connect()
    set_params(node, params, timeout=options.timeout)
    return 0


def do_dump(argv: List[str]) -> int:
    parser = _parser("Usage: %prog dump [options] node file")
    options, args = parser.parse_args(argv)
    node, path = _node_arg(parser, args, "an output file")
    connect()
    params = _get_or_fail(node, options.timeout)
    if params is None:
        print(f"couldn't get parameters from node {node}")
        return 0
    try:
        with open(path, "w") as f:
            yaml.dump(params, f)
    except OSError as exc:
        raise _Failed(f"cannot write {path}: {exc.strerror}") from None
    return 0


class DumpLoader(yaml.SafeLoader):
    """Safe YAML plus the one Python tag dump files carry (the Config dict type)."""


def _construct_config(loader: yaml.SafeLoader, node: yaml.Node) -> Any:
    from .encoding import Config

    config = Config()
    yield config
    fields = loader.construct_mapping(node, deep=True) if isinstance(node, yaml.MappingNode) else {}
    items = fields.get("dictitems") or {}
    if not isinstance(items, dict):
        raise yaml.constructor.ConstructorError(None, None, "dictitems is not a mapping",
                                                node.start_mark)
    config.update(items)


DumpLoader.add_constructor("tag:yaml.org,2002:python/object/new:dynamic_reconfigure.encoding.Config",
                           _construct_config)

COMMANDS: Dict[str, Callable[[List[str]], int]] = {
    "list": do_list, "set_from_parameters": do_set_from_parameters, "set": do_set,
    "get": do_get, "load": do_load, "dump": do_dump,
}


def main(argv: List[str] | None = None) -> int:
    args = minros.myargv(sys.argv if argv is None else argv)
    command = COMMANDS.get(args[1]) if len(args) > 1 else None
    if command is None:
        print(USAGE)
        return 1
    try:
        return command(args[2:])
    except _Failed as exc:
        print(exc)
        return 1
    except minros.ROSInterruptException:
        return 0
    except KeyboardInterrupt:
        return 1


if __name__ == "__main__":
    sys.exit(main())
