"""``minros ros2``: bridge the master of ROS_MASTER_URI with a ROS 2 domain (ros1_bridge).

    minros ros2 [--domain N] [--distro jazzy|kilted] [--bridge-all-topics]
                [--bridge-all-1to2-topics] [--bridge-all-2to1-topics]
                [--config bridge.yaml | --parameters] [--queue-size N] [--name NAME]
    minros ros2 --print-pairs [--distro ...]

Without a configuration it bridges as ros1_bridge's ``dynamic_bridge``; with one (a YAML file,
or the ``topics``/``services_1_to_2``/``services_2_to_1`` parameters), exactly what it lists,
as ``parameter_bridge``. No ROS 2 installation is needed: the DDS side is minros's own.
"""

from __future__ import annotations

import argparse
import os
import sys
from typing import List, Optional

from minros.tools.common import strip_ros_args

#: the distros whose type definitions (and so type hashes) minros bundles for the bridge
DISTROS = ("jazzy", "kilted", "humble")


def _parser(prog: str) -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(
        prog=prog,
        description="Bridge the ROS master at ROS_MASTER_URI with a ROS 2 domain, as ros1_bridge "
                    "does, without a ROS 2 installation: a topic with a publisher on one side "
                    "and a subscriber on the other is carried across, both ways, and every "
                    "service is offered on the other side. The bridge is a node in both graphs "
                    "(rosnode info, ros2 node list). Types map by ros1_bridge's rules; a ROS 1 "
                    "type without a ROS 2 counterpart gets one made from its definition.",
        epilog="The ROS 2 side speaks DDS (RTPS) on the loopback interface by default, as "
               "ROS_AUTOMATIC_DISCOVERY_RANGE=LOCALHOST does; ROS_DOMAIN_ID chooses the domain "
               "when --domain does not. Configuration file: ros1_bridge's parameter_bridge form "
               "(topics with topic, type, queue_size, qos; services_1_to_2 and services_2_to_1 "
               "with service, type); see docs/ros2.md, 'The bridge'.")
    parser.add_argument("--domain", type=int, default=None, metavar="N",
                        help="ROS 2 domain id, 0-232 (default: ROS_DOMAIN_ID, else 0)")
    default_distro = os.environ.get("ROS_DISTRO", "")
    parser.add_argument("--distro", choices=DISTROS,
                        default=default_distro if default_distro in DISTROS else "jazzy",
                        help="the ROS 2 distribution on the other side, whose type definitions "
                             "and hashes the bridge uses (default: ROS_DISTRO when it names "
                             "one of these, else jazzy)")
    parser.add_argument("--bridge-all-topics", action="store_true",
                        help="bridge every topic both ways, whether or not the other side "
                             "subscribes to it")
    parser.add_argument("--bridge-all-1to2-topics", action="store_true",
                        help="bridge every ROS 1 topic to ROS 2, whether or not ROS 2 "
                             "subscribes to it")
    parser.add_argument("--bridge-all-2to1-topics", action="store_true",
                        help="bridge every ROS 2 topic to ROS 1, whether or not ROS 1 "
                             "subscribes to it")
    source = parser.add_mutually_exclusive_group()
    source.add_argument("--config", metavar="FILE",
                        help="bridge exactly the topics and services of this YAML file "
                             "(parameter_bridge's form)")
    source.add_argument("--parameters", action="store_true",
                        help="bridge exactly the topics and services of the parameters topics, "
                             "services_1_to_2 and services_2_to_1 (parameter_bridge: "
                             "`rosparam load bridge.yaml` first)")
    parser.add_argument("--queue-size", type=int, default=10, metavar="N",
                        help="ROS 1 queue size and ROS 2 history depth of the dynamic bridges "
                             "(default 10, as dynamic_bridge)")
    parser.add_argument("--service-timeout", type=float, default=5.0, metavar="SECONDS",
                        help="how long a ROS 1 client's call waits for the ROS 2 service "
                             "(default 5)")
    parser.add_argument("--name", default="ros_bridge",
                        help="node name in both graphs (default ros_bridge, as ros1_bridge)")
    parser.add_argument("--print-pairs", action="store_true",
                        help="print the ROS 2 <=> ROS 1 message and service pairs that map "
                             "without a made type, and exit")
    return parser


def main(argv: List[str], prog: Optional[str] = None) -> int:
    prog = prog or "minros ros2"
    argv = strip_ros_args(list(argv))
    args = _parser(prog).parse_args(argv)

    def usage(text: str) -> int:
        print(f"{prog}: error: {text}", file=sys.stderr)
        return 2

    if args.print_pairs:
        return _print_pairs(args.distro)
    if args.domain is not None and not 0 <= args.domain <= 232:
        return usage(f"--domain {args.domain}: a number from 0 to 232")
    if args.queue_size < 1:
        return usage("--queue-size must be 1 or more")
    if args.service_timeout <= 0:
        return usage("--service-timeout must be positive")
    if args.domain is None:
        from minros.ros2.rmw.node import domain_from_env

        try:
            domain_from_env()
        except ValueError as exc:
            return usage(str(exc))
    from minros.ros2.bridge import config as configuration

    config = None
    if args.config:
        try:
            config = configuration.load(args.config)
        except configuration.ConfigError as exc:
            return usage(str(exc))
    error = _master_error()
    if error:
        print(f"{prog}: error: {error}", file=sys.stderr)
        return 1
    # the ROS 2 node first, before the rest is imported: ROS 2's graph lists it at once
    from minros.ros2.rmw import Context
    from minros.ros2.rmw.names import NameError_

    context = Context(args.domain)
    try:
        node = context.create_node(args.name)
    except NameError_ as exc:
        context.shutdown()
        return usage(f"--name {args.name}: {exc}")
    from minros.ros2.bridge.runtime import BridgeOptions, run

    options = BridgeOptions(
        distro=args.distro, name=args.name,
        bridge_all_1to2=args.bridge_all_topics or args.bridge_all_1to2_topics,
        bridge_all_2to1=args.bridge_all_topics or args.bridge_all_2to1_topics,
        queue_size=args.queue_size, config=config, service_timeout=args.service_timeout)
    return run(options, context, node, config_from_parameters=args.parameters,
               announce=lambda text: print(text, flush=True))


def _master_error() -> Optional[str]:
    """Why the ROS master cannot be used, or None (asked before anything joins DDS)."""
    from minros.tools.master import Master, MasterIOError

    master = Master("/minros_ros2", timeout=2.0)
    try:
        master.get_pid()
        return None
    except MasterIOError:
        return (f"cannot reach the ROS master at {master.uri}: start one with `minros core` "
                "(or roscore), or set ROS_MASTER_URI")
    except Exception as exc:  # noqa: BLE001 - any other answer: say what it was
        return f"the ROS master at {master.uri} does not answer: {exc}"
    finally:
        master.close()


def _print_pairs(distro: str) -> int:
    """ros1_bridge's --print-pairs: the pairs the mapping rules give without making a type."""
    from minros.msgs.registry import list_types
    from minros.packages import list_packages
    from minros.ros2.types import Mapper

    mapper = Mapper(distro)
    messages, services = [], []
    for package in sorted(list_packages()):
        try:
            names = list_types(package)
        except LookupError:
            continue
        for name in names:
            try:
                m = mapper.message(name)
            except Exception:  # noqa: BLE001 - broken or unmappable: not a pair
                continue
            if not m.generated:
                messages.append((m.ros2_type, name))
        try:
            service_names = list_types(package, "srv")
        except LookupError:
            service_names = []
        for name in service_names:
            try:
                s = mapper.service(name)
            except Exception:  # noqa: BLE001 - broken or unmappable: not a pair
                continue
            if not s.generated:
                services.append((s.ros2_type, name))
    print("Supported ROS 2 <=> ROS 1 message type conversion pairs:")
    for ros2, ros1 in sorted(messages):
        print(f"  - '{ros2}' (ROS 2) <=> '{ros1}' (ROS 1)")
    print("Supported ROS 2 <=> ROS 1 service type conversion pairs:")
    for ros2, ros1 in sorted(services):
        print(f"  - '{ros2}' (ROS 2) <=> '{ros1}' (ROS 1)")
    print("Any other ROS 1 type is bridged under a ROS 2 type made from its definition.")
    return 0

