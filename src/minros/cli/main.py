"""``minros`` entry point: dispatches ``minros TOOL ...`` and the ROS-named aliases.

Every tool is a module ``minros.cli.<module>`` exposing ``main(argv: list[str]) -> int``;
its own argparse parser gives ``--help``. The ROS names (``roscore``, ``rostopic``, ...)
are console scripts that call the same functions, so both spellings behave identically.
"""

from __future__ import annotations

import importlib
import sys
from typing import Callable, Dict, List, Optional, Tuple

#: sub-command -> (module, one-line summary)
COMMANDS: Dict[str, Tuple[str, str]] = {
    "core": ("minros.cli.core", "run a ROS master with parameter server and rosout (roscore)"),
    "run": ("minros.cli.run", "run an executable of a package (rosrun)"),
    "launch": ("minros.cli.launch", "start nodes and parameters from a .launch file (roslaunch)"),
    "topic": ("minros.cli.topic", "list, echo, publish and measure topics (rostopic)"),
    "node": ("minros.cli.node", "list, inspect, ping and kill nodes (rosnode)"),
    "param": ("minros.cli.param", "get, set, dump and load parameters (rosparam)"),
    "service": ("minros.cli.service", "list, inspect and call services (rosservice)"),
    "msg": ("minros.cli.msg", "show, hash and generate message types (rosmsg)"),
    "srv": ("minros.cli.srv", "show and hash service types (rossrv)"),
    "graph": ("minros.cli.graph", "draw the node/topic graph as DOT, SVG or PNG (rqt_graph)"),
    "pkg": ("minros.cli.pkg", "find and list packages (rospack)"),
    "version": ("minros.cli.rosversion", "print a package's version or the ROS distribution (rosversion)"),
    "ws": ("minros.cli.ws", "catkin workspaces: init, create_pkg, make"),
    "web": ("minros.cli.web", "rosbridge, rosapi, Foxglove and video for browsers, on one port"),
    "bag": ("minros.cli.bag", "record, play, inspect and convert bag files (rosbag)"),
    "test": ("minros.cli.rostest", "run the <test> nodes of a launch file (rostest)"),
    "unit": ("minros.cli.rosunit", "run a test program, its results as JUnit XML (rosunit)"),
    "links": ("minros.cli.rosgraph", "print each node's inbound and outbound peers and the "
                                     "services, every second (rosgraph)"),
    "console": ("minros.cli.console", "print log messages, list and set logger levels (rosconsole)"),
    "sim": ("minros.cli.sim", "a 2D robot simulator with map_server and move_base (Stage-like)"),
    "trace": ("minros.cli.trace", "trace the wire: XML-RPC, TCPROS headers and frames; show, pcap"),
    "clean": ("minros.cli.clean", "check the size of the ROS log files and purge them (rosclean)"),
    "wtf": ("minros.cli.wtf", "check the ROS environment and the running graph (roswtf)"),
    "master": ("minros.master", "run a ROS master alone, without rosout (rosmaster)"),
    "learn": ("minros.cli.learn", "exercises on the ROS wire that check themselves"),
    "zenoh": ("minros.cli.zenoh", "bridge topics and services with Zenoh (zenoh-bridge-ros1's wire)"),
    "ros2": ("minros.cli.ros2", "bridge topics and services with a ROS 2 domain (ros1_bridge)"),
}

#: ROS command name -> (sub-command, arguments put before the user's)
ALIASES: Dict[str, Tuple[str, List[str]]] = {
    "roscore": ("core", []),
    "rosrun": ("run", []),
    "roslaunch": ("launch", []),
    "rostopic": ("topic", []),
    "rosnode": ("node", []),
    "rosparam": ("param", []),
    "rosservice": ("service", []),
    "rosmsg": ("msg", []),
    "rossrv": ("srv", []),
    "rqt_graph": ("graph", []),
    "rospack": ("pkg", []),
    "rosversion": ("version", []),
    "catkin_init_workspace": ("ws", ["init"]),
    "catkin_create_pkg": ("ws", ["create_pkg"]),
    "catkin_make": ("ws", ["make"]),
    "rosbag": ("bag", []),
    "rostest": ("test", []),
    "rosunit": ("unit", []),
    "rosgraph": ("links", []),
    "rosconsole": ("console", []),
    "rosclean": ("clean", []),
    "roswtf": ("wtf", []),
    "rosmaster": ("master", []),
}


def _usage() -> str:
    width = max(len(name) for name in COMMANDS)
    lines = ["usage: minros COMMAND [ARGS...]", "", "commands:"]
    for name, (_module, summary) in COMMANDS.items():
        lines.append(f"  {name.ljust(width)}  {summary}")
    lines.append("")
    lines.append("ROS names work too: " + ", ".join(sorted(ALIASES)))
    lines.append("Run 'minros COMMAND --help' for the options of a command, "
                 "'minros --version' for the version.")
    return "\n".join(lines)


def run(command: str, argv: List[str], prog: Optional[str] = None) -> int:
    """Run sub-command ``command`` with ``argv``; returns the exit status."""
    module_name, _summary = COMMANDS[command]
    try:
        module = importlib.import_module(module_name)
    except ModuleNotFoundError as exc:
        if exc.name != module_name:
            raise
        print(f"minros: '{command}' is not available in this version of minros", file=sys.stderr)
        return 1
    from minros.rosenv import MasterURIError

    try:
        return int(module.main(argv, prog=prog or f"minros {command}") or 0)
    except MasterURIError as exc:  # ROS_MASTER_URI=localhost:11311: the value and its fix
        sys.stdout.flush()
        print(f"ERROR: {exc}", file=sys.stderr)
        return 1
    except KeyboardInterrupt:
        return 130
    except BrokenPipeError:
        # `rostopic echo /x | head`: the reader went away; not an error worth a traceback.
        # Point stdout at devnull so the interpreter's final flush does not raise again.
        import os

        os.dup2(os.open(os.devnull, os.O_WRONLY), sys.stdout.fileno())
        return 0


def _version() -> str:
    """What ``minros --version`` prints: the version, where it runs from (an editable install
    shows its clone), the Python and the ROS distribution minros speaks."""
    import os
    import platform

    import minros
    from minros.cli.rosversion import ROSDISTRO

    return (f"minros {minros.__version__} from {os.path.dirname(os.path.abspath(minros.__file__))} "
            f"(Python {platform.python_version()}, ROS 1 {ROSDISTRO})")


def main(argv: Optional[List[str]] = None) -> int:
    args = list(sys.argv[1:] if argv is None else argv)
    if not args or args[0] in ("-h", "--help", "help"):
        print(_usage())
        return 0
    if args[0] in ("--version", "-V"):
        print(_version())
        return 0
    command, prefix = ALIASES.get(args[0], (args[0], []))
    args[1:1] = prefix
    if command not in COMMANDS:
        print(f"minros: unknown command '{args[0]}'", file=sys.stderr)
        print(_usage(), file=sys.stderr)
        return 2
    return run(command, args[1:])


def _alias(ros_name: str) -> Callable[[], int]:
    def entry() -> int:
        command, prefix = ALIASES[ros_name]
        return run(command, prefix + sys.argv[1:], prog=ros_name)

    entry.__name__ = ros_name
    return entry


# Console-script targets, one per ROS command name (see pyproject.toml).
roscore = _alias("roscore")
rosrun = _alias("rosrun")
roslaunch = _alias("roslaunch")
rostopic = _alias("rostopic")
rosnode = _alias("rosnode")
rosparam = _alias("rosparam")
rosservice = _alias("rosservice")
rosmsg = _alias("rosmsg")
rossrv = _alias("rossrv")
rqt_graph = _alias("rqt_graph")
rospack = _alias("rospack")
rosversion = _alias("rosversion")
catkin_init_workspace = _alias("catkin_init_workspace")
catkin_create_pkg = _alias("catkin_create_pkg")
catkin_make = _alias("catkin_make")
rosbag = _alias("rosbag")
rostest = _alias("rostest")
rosunit = _alias("rosunit")
rosgraph = _alias("rosgraph")
rosconsole = _alias("rosconsole")
rosclean = _alias("rosclean")
roswtf = _alias("roswtf")
rosmaster = _alias("rosmaster")

if __name__ == "__main__":
    sys.exit(main())
