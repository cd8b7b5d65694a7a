"""``minros param`` / ``rosparam``: get, set, list, delete, dump and load parameters.

Output and error texts follow Debian's rosparam (ros_comm 1.15): YAML via PyYAML, ``set``
with a dictionary merges key by key (the master API would replace the namespace), ``load``
reads one or more YAML documents from a file or stdin (``-``) with ``_ns`` support.
"""

from __future__ import annotations

import optparse
import os
import sys
import xmlrpc.client
from typing import Any, Callable, List, Tuple

import yaml

from minros import names
from minros.tools.common import ToolError, dispatch, option_parser, resolve, run_tool
from minros.tools.master import Master

NAME = "rosparam"
USAGE = """rosparam is a command-line tool for getting, setting, and deleting parameters from the ROS Parameter Server.

Commands:
\trosparam set\tset parameter
\trosparam get\tget parameter
\trosparam load\tload parameters from file
\trosparam dump\tdump parameters to file
\trosparam delete\tdelete parameter
\trosparam list\tlist parameter names
"""
MAX_INT = 2 ** 31 - 1


class _Dumper(yaml.Dumper):
    """yaml.Dumper that writes XML-RPC Binary values as ``!!binary`` (as rosparam does)."""


def _represent_binary(dumper: yaml.Dumper, data: xmlrpc.client.Binary) -> Any:
    import base64

    return dumper.represent_scalar("tag:yaml.org,2002:binary",
                                   base64.b64encode(data.data).decode("ascii"), style="|")


_Dumper.add_representer(xmlrpc.client.Binary, _represent_binary)


def _loader() -> type:
    from minros.launch.rosparam_yaml import RosparamLoader

    return RosparamLoader


def yaml_load(text: str) -> Any:
    from minros.launch.rosparam_yaml import load_yaml

    try:
        return load_yaml(text)  # YAML errors come back as ValueError, like bad angle values
    except ValueError as exc:
        raise ToolError(f"invalid YAML: {_one_line(exc)}") from None
    except RecursionError:
        raise ToolError(f"invalid YAML: {TOO_DEEP}") from None


#: PyYAML composes nested collections recursively: past ~300 levels it runs out of stack
TOO_DEEP = "collections nested too deeply to be a parameter (keep it under 200 levels)"


def read_text(data: bytes, source: str) -> str:
    """The text of a parameter file (UTF-8, as YAML is), or one line saying where it is not."""
    try:
        return data.decode("utf-8")
    except UnicodeDecodeError as exc:
        line = data.count(b"\n", 0, exc.start) + 1
        raise ToolError(f"{source} is not UTF-8 text: byte 0x{data[exc.start]:02x} on line {line} "
                        "(save it as UTF-8)") from None


def _one_line(exc: BaseException) -> str:
    return " ".join(str(exc).split())


def dump_yaml(value: Any) -> str:
    return yaml.dump(value, Dumper=_Dumper)


def _master() -> Master:
    return Master(names.make_caller_id(f"rosparam-{os.getpid()}").rstrip("/"))


# ---------------------------------------------------------------------------------------------
# operations (library API too)

def set_param_raw(master: Master, param: str, value: Any, verbose: bool = False) -> None:
    """Set ``param``; dictionaries are merged key by key as rosparam does."""
    if isinstance(value, dict):
        for key, sub in value.items():
            if not isinstance(key, str):
                raise ToolError(f"YAML dictionaries must have string keys. Invalid dictionary is: {value}")
            set_param_raw(master, names.ns_join(param, key), sub, verbose)
        return
    _check_xmlrpc_value(value)
    master.setParam(param, value)
    if verbose:
        print(f"set parameter [{param}] to [{value}]")


def _check_xmlrpc_value(value: Any) -> None:
    if value is None:
        raise ToolError("cannot set a parameter to an empty value (null is not an XML-RPC value)")
    if isinstance(value, bool):
        return
    if isinstance(value, int):
        if not -MAX_INT - 1 <= value <= MAX_INT:
            raise ToolError("Overflow: Parameter Server integers must be 32-bit signed integers: "
                            f"{-MAX_INT - 1} <= value <= {MAX_INT}")
    elif isinstance(value, (list, tuple)):
        for item in value:
            _check_xmlrpc_value(item)
    elif isinstance(value, dict):
        for key, item in value.items():
            if not isinstance(key, str):
                raise ToolError(f"YAML dictionaries must have string keys. Invalid dictionary is: {value}")
            _check_xmlrpc_value(item)
    elif isinstance(value, (float, str, xmlrpc.client.Binary)):
        return
    elif hasattr(value, "isoformat"):
        return
    else:
        raise ToolError(f"cannot store a value of type {type(value).__name__} on the parameter server")


def list_params(master: Master, ns: str) -> List[str]:
    ns = names.make_global_ns(ns)
    return sorted(n for n in master.getParamNames() if n.startswith(ns))


def load_documents(text: str, default_ns: str, verbose: bool = False) -> List[Tuple[Any, str]]:
    try:
        docs = list(yaml.load_all(text, Loader=_loader()))  # noqa: S506 - SafeLoader subclass
    except (yaml.YAMLError, ValueError) as exc:
        raise ToolError(f"invalid YAML: {_one_line(exc)}") from None
    except RecursionError:
        raise ToolError(f"invalid YAML: {TOO_DEEP}") from None
    out = []
    for doc in docs:
        if doc is None:
            continue
        ns = default_ns
        if isinstance(doc, dict) and "_ns" in doc:
            ns = names.ns_join(default_ns, doc.pop("_ns"))
            if verbose:
                print(f"reading parameters into namespace [{ns}]")
        out.append((doc, ns))
    return out


def print_params(params: Any, ns: str) -> None:
    if isinstance(params, dict):
        for key, value in params.items():
            if isinstance(value, dict):
                print_params(value, names.ns_join(ns, key))
            else:
                print(f"{names.ns_join(ns, key)}={value}")
    else:
        print(params)


def _pretty_print(value: dict, indent: str = "") -> None:
    for key in sorted(value):
        item = value[key]
        if isinstance(item, dict):
            print(f"{indent}{key}:")
            _pretty_print(item, indent + "  ")
        elif isinstance(item, str):
            if "\n" in item:
                print(f"{indent}{key}: |")
                for line in item.split("\n"):
                    print(f"{indent}  {line}")
            else:
                print(f"{indent}{key}: {item}")
        else:
            text = dump_yaml(item)
            if text.endswith("\n...\n"):
                text = text[:-4]
            sys.stdout.write(f"{indent}{key}: {text}")


# ---------------------------------------------------------------------------------------------
# commands

def _cmd_get(argv: List[str], prog: str) -> int:
    p = option_parser(prog, " [options] parameter")
    p.add_option("-p", dest="pretty", default=False, action="store_true", help="pretty print. WARNING: not YAML-safe")
    p.add_option("-v", dest="verbose", default=False, action="store_true", help="turn on verbose output")
    args, parameters = p.parse_args(argv)
    if not parameters:
        p.error("invalid arguments. Please specify a parameter name")
    if len(parameters) > 1:
        p.error("too many arguments")
    name = resolve(NAME, parameters[0])
    if args.verbose:
        print(f"getting parameter [{name}]")
    value = _master().getParam(name)
    if args.pretty and isinstance(value, (dict, str)):
        if isinstance(value, dict):
            _pretty_print(value)
        else:
            print(value)
    else:
        text = dump_yaml(value)
        if text.endswith("\n...\n"):
            text = text[:-5]
        sys.stdout.write(f"{text}\n")
    return 0


def _cmd_dump(argv: List[str], prog: str) -> int:
    p = option_parser(prog, " [options] file [namespace]")
    p.add_option("-v", dest="verbose", default=False, action="store_true", help="turn on verbose output")
    args, positional = p.parse_args(argv)
    if len(positional) > 2:
        p.error("too many arguments")
    args.file = positional[0] if positional else None
    args.namespace = positional[1] if len(positional) > 1 else ""
    if args.verbose:
        print(f"dumping namespace [{args.namespace}] to file [{args.file}]")
    ns = resolve(NAME, args.namespace)
    tree = _master().getParam(ns)
    if args.verbose:
        print_params(tree, ns)
    text = dump_yaml(tree)
    if not args.file or args.file == "-":
        sys.stdout.write(text)
    else:
        try:
            with open(args.file, "w") as f:
                f.write(text)
        except OSError as exc:
            raise ToolError(f"cannot write [{args.file}]: {exc.strerror}") from None
    return 0


def _split_set_args(argv: List[str], p: optparse.OptionParser | None = None) -> Tuple[List[str], List[str]]:
    """Negative numbers are values, not options (as rosparam's own parser does); an option
    where -t/-b expect their file is a usage error reported through ``p``."""
    p = p or option_parser(f"{NAME} set")
    opts, positional = [], []
    skip = False
    for arg in argv:
        if skip and arg.startswith("-"):
            p.error("-t and --textfile options require an argument")  # rosparam's words, also for -b
        if skip:
            opts.append(arg)
            skip = False
        elif arg in ("-t", "--textfile", "-b", "--binfile"):
            opts.append(arg)
            skip = True
        elif arg.startswith("-") and len(arg) > 1 and (arg[1].isdigit() or arg[1] == "."):
            positional.append(arg)
        elif arg.startswith("-") and len(arg) > 1:
            opts.append(arg)
        else:
            positional.append(arg)
    return opts, positional


def _cmd_set(argv: List[str], prog: str) -> int:
    p = option_parser(prog, " [options] parameter value")
    p.add_option("-t", "--textfile", dest="text_file", default=None, metavar="TEXT_FILE",
                 help="set parameters to contents of text file")
    p.add_option("-b", "--binfile", dest="bin_file", default=None, metavar="BINARY_FILE",
                 help="set parameters to contents of binary file")
    p.add_option("-v", dest="verbose", default=False, action="store_true", help="turn on verbose output")
    opts, positional = _split_set_args(argv, p)
    args, _none = p.parse_args(opts)
    if args.text_file and args.bin_file:
        p.error("you may only specify one of --textfile or --binfile")
    if not positional:
        p.error("invalid arguments. Please specify a parameter name")
    if len(positional) > 2:
        p.error("too many arguments")
    if len(positional) == 1 and not (args.text_file or args.bin_file):
        p.error("invalid arguments. Please specify a parameter value")
    name = resolve(NAME, positional[0])
    master = _master()
    if args.text_file:
        if not os.path.isfile(args.text_file):
            p.error(f"file '{args.text_file}' does not exist")
        with open(args.text_file, "rb") as f:
            text = read_text(f.read(), f"file [{args.text_file}]")
        set_param_raw(master, name, text, args.verbose)
    elif args.bin_file:
        try:
            with open(args.bin_file, "rb") as f:
                data = f.read()
        except OSError as exc:
            raise ToolError(f"cannot read [{args.bin_file}]: {exc.strerror}") from None
        set_param_raw(master, name, xmlrpc.client.Binary(data), args.verbose)
    else:
        text = positional[1]
        value = yaml_load(text) if text != "" else ""
        set_param_raw(master, name, value, args.verbose)
    return 0


def _cmd_load(argv: List[str], prog: str) -> int:
    p = option_parser(prog, " [options] file [namespace]")
    p.add_option("-v", dest="verbose", default=False, action="store_true", help="turn on verbose output")
    args, positional = p.parse_args(argv)
    if not positional:
        p.error("invalid arguments. Please specify a file name or - for stdin")
    if len(positional) > 2:
        p.error("too many arguments")
    args.file = positional[0]
    args.namespace = positional[1] if len(positional) > 1 else None
    default_ns = resolve(NAME, args.namespace) if args.namespace else names.get_ros_namespace()
    if args.file == "-":
        if args.verbose:
            print("reading parameters from stdin")
        text = read_text(sys.stdin.buffer.read(), "stdin")
    else:
        if not os.path.isfile(args.file):
            raise ToolError(f"file [{args.file}] does not exist")
        if args.verbose:
            print(f"reading parameters from [{args.file}]")
        with open(args.file, "rb") as f:
            text = read_text(f.read(), f"file [{args.file}]")
    master = _master()
    for params, ns in load_documents(text, default_ns, args.verbose):
        if ns == "/" and not isinstance(params, dict):
            raise ToolError("global / can only be set to a dictionary")
        if args.verbose:
            print_params(params, ns)
        set_param_raw(master, ns, params)
    return 0


def _cmd_delete(argv: List[str], prog: str) -> int:
    p = option_parser(prog, " [options] parameter")
    p.add_option("-v", dest="verbose", default=False, action="store_true", help="turn on verbose output")
    args, parameters = p.parse_args(argv)
    if not parameters:
        p.error("invalid arguments. Please specify a parameter name")
    if len(parameters) > 1:
        p.error("too many arguments")
    name = resolve(NAME, parameters[0])
    master = _master()
    if name == "/":
        master.setParam("/", {})
        if args.verbose:
            print("deleted ENTIRE parameter server")
    else:
        master.deleteParam(name)
        if args.verbose:
            print(f"deleted parameter [{name}]")
    return 0


def _cmd_list(argv: List[str], prog: str) -> int:
    p = option_parser(prog, " [namespace]")
    _options, namespaces = p.parse_args(argv)
    if len(namespaces) > 1:
        # rosparam only objects to exactly two (three or more silently list everything)
        p.error("too many arguments")
    ns = resolve(NAME, namespaces[0]) if namespaces else "/"
    print("\n".join(list_params(_master(), ns)))
    return 0


COMMANDS = {"get": _cmd_get, "set": _cmd_set, "load": _cmd_load, "dump": _cmd_dump,
            "delete": _cmd_delete, "list": _cmd_list}


def main(argv: List[str], prog: str = "rosparam") -> int:
    return run_tool(lambda: dispatch(argv, prog, COMMANDS, USAGE))


# ---------------------------------------------------------------------------------------------
# the Python API of ROS's rosparam module (the stand-in re-exports it): the same code as the
# commands, raising RosParamException instead of exiting


class RosParamException(Exception):
    """A rosparam call failed."""


class RosParamIOException(RosParamException):
    """The master could not be reached."""


def _library(fn: Callable[[], Any]) -> Any:
    from minros.tools.common import library_call

    return library_call(fn, RosParamException, RosParamIOException)


def load_file(filename: str, default_namespace: str | None = None,
              verbose: bool = False) -> List[Tuple[Any, str]]:
    """The YAML documents of ``filename`` as ``[(values, namespace), ...]`` (``_ns`` keys
    honoured); nothing is set yet."""
    def run() -> List[Tuple[Any, str]]:
        ns = resolve(NAME, default_namespace or "")
        try:
            with open(filename, "rb") as f:
                data = f.read()
        except OSError as exc:
            raise ToolError(f"file [{filename}] does not exist: {exc.strerror}") from None
        return load_documents(read_text(data, f"file [{filename}]"), ns, verbose)

    return _library(run)


def upload_params(ns: str, values: Any, verbose: bool = False) -> None:
    """Set ``values`` under namespace ``ns`` (dictionaries merged key by key)."""
    _library(lambda: set_param_raw(_master(), resolve(NAME, ns), values, verbose))


def get_param(param: str) -> Any:
    """The value of ``param`` (a namespace gives a dictionary)."""
    return _library(lambda: _master().getParam(resolve(NAME, param)))


def set_param(param: str, value: str, verbose: bool = False) -> None:
    """Set ``param`` from ``value`` given as YAML text, as ``rosparam set`` does."""
    _library(lambda: set_param_raw(_master(), resolve(NAME, param), yaml_load(value), verbose))


def delete_param(param: str, verbose: bool = False) -> None:
    def run() -> None:
        name = resolve(NAME, param)
        _master().deleteParam(name)
        if verbose:
            print(f"deleted parameter [{name}]")

    _library(run)


def list_params_api(ns: str) -> List[str]:
    return _library(lambda: list_params(_master(), resolve(NAME, ns)))


def dump_params(filename: str, param: str, verbose: bool = False) -> None:
    """Write the parameters under ``param`` to ``filename`` as YAML (``rosparam dump``)."""
    def run() -> None:
        ns = resolve(NAME, param)
        tree = _master().getParam(ns)
        if verbose:
            print_params(tree, ns)
        try:
            with open(filename, "w") as f:
                f.write(dump_yaml(tree))
        except OSError as exc:
            raise ToolError(f"cannot write [{filename}]: {exc.strerror}") from None

    _library(run)


def yamlmain(argv: List[str] | None = None) -> None:
    """The rosparam command (``argv`` as sys.argv, program name first)."""
    sys.exit(main(list(sys.argv if argv is None else argv)[1:]))


# -- more of rosparam's Python API: its YAML hooks and helpers (the angle and binary tags are
# minros.launch.rosparam_yaml's, on a loader of their own: importing rosparam patches nothing)

#: the key of a YAML document that names the namespace it loads into
NS = "_ns"


def get_param_server() -> Master:
    """The master client rosparam's calls go through (caller id ``/rosparam-<pid>``)."""
    return _master()


def load_str(text: str, filename: str | None, default_namespace: str | None = None,
             verbose: bool = False) -> List[Tuple[Any, str]]:
    """``[(values, namespace), ...]`` for the YAML documents in ``text`` (``_ns`` keys
    honoured; ``filename`` only names the source)."""
    def run() -> List[Tuple[Any, str]]:
        return load_documents(text, default_namespace or names.get_ros_namespace(), verbose)

    return _library(run)


def construct_angle_radians(loader: Any, node: Any) -> float:
    """YAML constructor of ``!radians 2*pi`` / ``rad(pi/2)``: the value in radians."""
    from minros.launch.rosparam_yaml import RosparamLoader

    try:
        return RosparamLoader.yaml_constructors["!radians"](loader, node)
    except ValueError as exc:
        raise RosParamException(str(exc)) from None


def construct_angle_degrees(loader: Any, node: Any) -> float:
    """YAML constructor of ``!degrees 180`` / ``deg(90)``: the value in radians."""
    from minros.launch.rosparam_yaml import RosparamLoader

    try:
        return RosparamLoader.yaml_constructors["!degrees"](loader, node)
    except ValueError as exc:
        raise RosParamException(str(exc)) from None


def construct_yaml_binary(loader: Any, node: Any) -> xmlrpc.client.Binary:
    """YAML constructor of ``!!binary``: an XML-RPC Binary, as the parameter server stores it."""
    return xmlrpc.client.Binary(loader.construct_yaml_binary(node))


def represent_xml_binary(dumper: Any, data: xmlrpc.client.Binary) -> Any:
    """YAML representer of an XML-RPC Binary: ``!!binary`` base64 text."""
    return _represent_binary(dumper, data)


def represent_foo(dumper: Any, data: Any) -> Any:
    """rosparam's representer writing ``data`` as a scalar tagged ``#``."""
    return dumper.represent_scalar("#", data)


if __name__ == "__main__":  # rosrun rosparam rosparam / <node pkg="rosparam" type="rosparam">
    sys.exit(main(sys.argv[1:]))
