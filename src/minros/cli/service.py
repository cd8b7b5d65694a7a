"""``minros service`` / ``rosservice``: list, info, type, uri, node, args, find and call.

Texts and exit statuses follow Debian's rosservice (ros_comm 1.15): expected failures print
``ERROR: ...`` and exit 2, unknown services in ``type``/``uri`` exit 1. A service's type is
read from the server's header through a probe connection (with a timeout).
"""

from __future__ import annotations

import io
import sys
from typing import Any, Callable, List

import yaml

from minros import names
from minros.tools.common import ToolError, dispatch, option_parser, resolve, run_tool
from minros.tools.master import Master, MasterError
from minros.tools.services import probe_service
from minros.wire import tcpros
from minros.wire.rosapi import ParameterInvalid

NAME = "rosservice"
PROBE_TIMEOUT = 5.0
USAGE = """Commands:
\trosservice args\tprint service arguments
\trosservice call\tcall the service with the provided args
\trosservice find\tfind services by service type
\trosservice info\tprint information about service
\trosservice list\tlist active services
\trosservice type\tprint service type
\trosservice uri\tprint service ROSRPC uri

Type rosservice <command> -h for more detailed usage, e.g. 'rosservice call -h'
"""


def _master() -> Master:
    return Master("/rosservice")


def _error(text: str) -> ToolError:
    return ToolError(text, status=2)


def get_service_headers(service: str, uri: str) -> dict:
    """Probe the server (``probe=1``) and return its connection header."""
    try:
        return probe_service(uri, service, "/rosservice", PROBE_TIMEOUT)
    except ParameterInvalid:
        raise _error(f"service [{service}] has an invalid RPC URI [{uri}]") from None
    except (OSError, tcpros.HeaderError):
        raise _error(f"Unable to communicate with service [{service}], address [{uri}]") from None


def get_service_uri(master: Master, service: str) -> str | None:
    try:
        return master.lookupService(service)
    except MasterError:
        return None


def get_service_type(master: Master, service: str) -> str | None:
    uri = get_service_uri(master, service)
    if uri is None:
        return None
    return get_service_headers(service, uri).get("type")


def get_service_list(master: Master, node: str | None = None, namespace: str | None = None,
                     include_nodes: bool = False) -> list:
    srvs = master.system_state()[2]
    if namespace:
        g_ns = names.make_global_ns(namespace)
        srvs = [s for s in srvs if s[0] == namespace or s[0].startswith(g_ns)]
    if node is not None:
        srvs = [s for s in srvs if node in s[1]]
    return srvs if include_nodes else [s for s, _ in srvs]


def get_service_node(master: Master, service: str) -> str | None:
    for name, nodes in get_service_list(master, include_nodes=True):
        if name == service and nodes:
            return nodes[0]
    return None


def get_service_class_by_name(master: Master, service: str) -> Any:
    from minros.msgs import UnknownTypeError, get_service_class

    service_type = get_service_type(master, service)
    if not service_type:
        if service not in get_service_list(master):
            raise _error(f"Service [{service}] is not available.")
        raise _error(f"Unable to determine type of service [{service}].")
    try:
        return get_service_class(service_type)
    except (UnknownTypeError, ValueError):
        pkg = service_type.split("/")[0] if "/" in service_type else None
        raise _error(f"Unable to load type [{service_type}]. Have you typed 'make' in [{pkg}]?") from None


def get_service_args(master: Master, service: str) -> str:
    from minros.msgs.fill import printable_message_args

    return printable_message_args(get_service_class_by_name(master, service)._request_class)


def _one_service(argv: List[str], prog: str, what: str) -> str:
    p = option_parser(prog, " /service")
    _options, services = p.parse_args(argv)
    if not services:
        p.error("service must be specified")
    if len(services) > 1:
        p.error("you may only specify one input service")
    return resolve(NAME, services[0])


# ---------------------------------------------------------------------------------------------
# commands

def _cmd_list(argv: List[str], prog: str) -> int:
    p = option_parser(prog, " [/namespace]")
    p.add_option("-n", "--nodes", dest="print_nodes", default=False, action="store_true",
                 help="print nodes that provide service(s)")
    args, namespaces = p.parse_args(argv)
    if len(namespaces) > 1:
        p.error("you may only specify one input namespace")
    namespace = resolve(NAME, namespaces[0]) if namespaces else None
    srvs = get_service_list(_master(), namespace=namespace, include_nodes=args.print_nodes)
    if args.print_nodes:
        for name, nodes in sorted(srvs, key=lambda s: s[0]):
            print(name + " " + ",".join(nodes))
    else:
        for name in sorted(srvs):
            print(name)
    return 0


def _cmd_type(argv: List[str], prog: str) -> int:
    service = _one_service(argv, prog, "type")
    service_type = get_service_type(_master(), service)
    if service_type is None:
        print(f"Unknown service [{service}]", file=sys.stderr)
        return 1
    print(service_type)
    return 0


def _cmd_uri(argv: List[str], prog: str) -> int:
    service = _one_service(argv, prog, "uri")
    uri = get_service_uri(_master(), service)
    if not uri:
        print(f"Unknown service: {service}", file=sys.stderr)
        return 1
    print(uri)
    return 0


def _cmd_node(argv: List[str], prog: str) -> int:
    service = _one_service(argv, prog, "node")
    node = get_service_node(_master(), service)
    if not node:
        print(f"Unknown service: {service}", file=sys.stderr)
        return 1
    print(node)
    return 0


def _cmd_args(argv: List[str], prog: str) -> int:
    service = _one_service(argv, prog, "args")
    print(get_service_args(_master(), service))
    return 0


def _cmd_info(argv: List[str], prog: str) -> int:
    p = option_parser(prog, " /service")
    _options, services = p.parse_args(argv)
    if len(services) > 1:
        p.error("you may only specify one service")
    if not services:
        p.error("you must specify a service name")
    service = resolve(NAME, services[0])
    master = _master()
    node = get_service_node(master, service)
    if not node:
        print("ERROR: unknown service", file=sys.stderr)
        return 1
    print(f"Node: {node}")
    uri = get_service_uri(master, service)
    if not uri:
        print("ERROR: service is no longer available", file=sys.stderr)
        return 0
    print(f"URI: {uri}")
    service_type = get_service_headers(service, uri).get("type")
    if not service_type:
        print("ERROR: service is no longer available", file=sys.stderr)
        return 0
    print(f"Type: {service_type}")
    print(f"Args: {get_service_args(master, service)}")
    return 0


def find_services(master: Master, service_type: str) -> List[str]:
    matches = []
    for service, _nodes in master.system_state()[2]:
        try:
            if get_service_type(master, service) == service_type:
                matches.append(service)
        except ToolError:
            continue
    return matches


def _cmd_find(argv: List[str], prog: str) -> int:
    p = option_parser(prog, " msg-type")
    _options, types = p.parse_args(argv)
    if not types:
        p.error("please specify a message type")
    if len(types) > 1:
        p.error("you may only specify one message type")
    print("\n".join(find_services(_master(), types[0])))
    return 0


def _summary(args: Any) -> str:
    items = args if isinstance(args, (list, tuple)) else [args]
    return ", ".join(f"{a!r} (type {type(a).__name__})" for a in items)


def call_service(master: Master, service: str, service_args: list, service_class: Any) -> tuple:
    from minros.client.services import ServiceProxy
    from minros.exceptions import MessageException, ServiceException
    from minros.msgs.fill import fill_message_args, printable_message_args, substitution_keys

    request = service_class._request_class()
    try:
        fill_message_args(request, service_args, substitution_keys())
    except (MessageException, ValueError, TypeError) as exc:
        raise _error("Incompatible arguments to call service: " + " ".join(str(exc).split())
                     + f" (provided: {_summary(service_args)}; service arguments are: "
                     f"[{printable_message_args(request)}])") from None
    try:
        request.serialize(io.BytesIO())  # wrong value types are reported before connecting
    except MessageException as exc:
        raise _error("Unable to send request. One of the fields has an incorrect type: "
                     + " ".join(str(exc).split())) from None
    try:
        response = ServiceProxy(service, service_class)(request)
    except ServiceException as exc:
        raise _error(" ".join(str(exc).split())) from None
    except MessageException as exc:
        raise _error("Unable to send request. One of the fields has an incorrect type: "
                     + " ".join(str(exc).split())) from None
    return request, response


def _yaml_args(texts: List[str]) -> list:
    out = []
    for text in texts:
        if text == "":
            text = "''"
        try:
            out.append(yaml.safe_load(text))
        except yaml.YAMLError as exc:
            raise _error("invalid YAML argument " + repr(text) + ": " + " ".join(str(exc).split())) from None
    return out


def _stdin_documents() -> Any:
    """YAML documents separated by ``---`` lines on stdin."""
    buff: List[str] = []
    for line in sys.stdin:
        if line.strip() == "---":
            if buff:
                yield "".join(buff)
            buff = []
        else:
            buff.append(line)
    if "".join(buff).strip():
        yield "".join(buff)


def _cmd_call(argv: List[str], prog: str) -> int:
    p = option_parser(prog, " /service [args...]")
    p.add_option("-v", dest="verbose", default=False, action="store_true", help="print verbose output")
    p.add_option("--wait", dest="wait", default=False, action="store_true",
                 help="wait for service to be advertised")
    # values such as -1 are arguments of the call, not options
    opts = [a for a in argv if a.startswith("-") and not a[1:2].isdigit() and a not in ("-", "-.")]
    rest = [a for a in argv if a not in opts]
    args, _none = p.parse_args(opts)
    if not rest:
        p.error("service must be specified")
    service = resolve(NAME, rest[0])
    master = _master()
    if args.wait:
        master.getPid()
        from minros.client.services import wait_for_service

        wait_for_service(service)
    service_class = get_service_class_by_name(master, service)
    service_args = _yaml_args(rest[1:])
    calls = [service_args]
    if not service_args and service_class._request_class.__slots__:
        if sys.stdin.isatty():
            p.error("Please specify service arguments")
        calls = []
        for doc in _stdin_documents():
            value = _yaml_args([doc])[0]
            if value is None:
                break
            calls.append(value if isinstance(value, list) else [value])
    for call_args in calls:
        request, response = call_service(master, service, call_args, service_class)
        if args.verbose:
            print(str(request))
            print("---")
        print(str(response))
        sys.stdout.flush()
    return 0


COMMANDS = {"list": _cmd_list, "info": _cmd_info, "type": _cmd_type, "uri": _cmd_uri,
            "node": _cmd_node, "call": _cmd_call, "args": _cmd_args, "find": _cmd_find}


def main(argv: List[str], prog: str = "rosservice") -> int:
    if argv[:1] in (["-h"], ["--help"]):
        # rosservice has no -h of its own: like any unknown command, the usage and EX_USAGE
        print(USAGE)
        return 64
    return run_tool(lambda: dispatch(argv, prog, COMMANDS, USAGE, usage_status=64), io_status=2)


# ---------------------------------------------------------------------------------------------
# the Python API of ROS's rosservice module (the stand-in re-exports it): the same code as the
# commands, raising rosservice's exceptions instead of exiting


class ROSServiceException(Exception):
    """A rosservice call failed."""


class ROSServiceIOException(ROSServiceException):
    """The master or the service could not be reached."""


def _library(fn: Callable[[], Any]) -> Any:
    from minros.tools.common import library_call

    return library_call(fn, ROSServiceException, ROSServiceIOException)


def _api(fn: Callable[..., Any]) -> Callable[..., Any]:
    """``fn(master, service, ...)`` as rosservice's ``fn(service, ...)``: the name resolved
    as the command resolves it, a master of its own."""
    def call(service: str, *args: Any, **kwds: Any) -> Any:
        return _library(lambda: fn(_master(), resolve(NAME, service), *args, **kwds))

    call.__name__ = fn.__name__
    call.__doc__ = fn.__doc__
    return call


rosservice_get_service_type = _api(get_service_type)
rosservice_get_service_uri = _api(get_service_uri)
rosservice_get_service_node = _api(get_service_node)
rosservice_get_service_class_by_name = _api(get_service_class_by_name)
rosservice_get_service_args = _api(get_service_args)


def rosservice_get_service_headers(service_name: str, service_uri: str) -> dict:
    return _library(lambda: get_service_headers(service_name, service_uri))


def rosservice_get_service_list(node: str | None = None, namespace: str | None = None,
                                include_nodes: bool = False) -> list:
    return _library(lambda: get_service_list(_master(), node, namespace, include_nodes))


def rosservice_call_service(service_name: str, service_args: list,
                            service_class: Any = None) -> tuple:
    """``(request, response)`` of calling ``service_name`` with YAML-parsed ``service_args``."""
    def run() -> tuple:
        master = _master()
        service = resolve(NAME, service_name)
        cls = service_class or get_service_class_by_name(master, service)
        return call_service(master, service, service_args, cls)

    return _library(run)


def rosservicemain(argv: List[str] | None = None) -> None:
    """The rosservice command (``argv`` as sys.argv, program name first)."""
    sys.exit(main(list(sys.argv if argv is None else argv)[1:]))


# -- more of rosservice's Python API

def has_service_args(service_name: str, service_class: Any = None) -> bool:
    """Whether the service's request has fields (``service_class`` saves asking the
    service for its type)."""
    def run() -> bool:
        cls = service_class or get_service_class_by_name(_master(), resolve(NAME, service_name))
        return len(cls._request_class.__slots__) > 0

    return _library(run)


def rosservice_find(service_type: str) -> List[str]:
    """The services of type ``service_type`` (``rosservice find``)."""
    return _library(lambda: find_services(_master(), service_type))


if __name__ == "__main__":  # rosrun rosservice rosservice
    sys.exit(main(sys.argv[1:]))
