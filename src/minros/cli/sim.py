"""``minros sim [WORLD.yaml] [options]``: a 2D robot simulator with a navigation stack to drive.

It is a roslaunch of generated XML (``--print-launch`` shows it): the simulator node
(``minros_sim/sim_node``, required), ``map_server`` serving the same map on ``/map``, and one
``move_base`` per robot (minros's teaching version) unless ``--no-nav``; ``--web PORT`` adds
``minros web``. Like roslaunch it starts a master when none answers at ROS_MASTER_URI, and
Ctrl-C stops everything. The world is checked before anything starts, so a bad map file is one
line and exit status 1.
"""

from __future__ import annotations

import argparse
import os
import shlex
import sys
from typing import List
from xml.sax.saxutils import quoteattr


def _parser(prog: str) -> argparse.ArgumentParser:
    from minros.nodes.minros_sim.sim_node import build_parser

    parser = build_parser(prog)
    parser.description = (
        "A 2D simulator in the spirit of Stage: TurtleBot3 Burger-like robots with a 360-beam "
        "laser on a map_server map, with map_server and a small move_base to send navigation "
        "goals to. Topics as TurtleBot3's: /cmd_vel, /scan, /odom, tf map -> odom -> "
        "base_footprint -> base_scan (under tb3_N/ when there are several robots). The "
        "top-down view is the image topic /sim/view (the page's Images view shows it).")
    parser.epilog = ("example: minros sim --web 9090, then open http://localhost:9090 and "
                     "send a goal: rostopic pub -1 /move_base_simple/goal "
                     "geometry_msgs/PoseStamped '{header: {frame_id: map}, pose: {position: "
                     "{x: 2.0, y: 0.0}, orientation: {w: 1.0}}}'")
    group = parser.add_argument_group("what minros sim starts")
    group.add_argument("--no-nav", action="store_true",
                       help="no move_base (drive the robots yourself on cmd_vel)")
    group.add_argument("--no-map-server", action="store_true",
                       help="no map_server (serve /map yourself, or do without)")
    group.add_argument("--web", type=int, metavar="PORT",
                       help="also run minros web on PORT (the page, rosbridge, Foxglove)")
    group.add_argument("--screen", action="store_true",
                       help="every node's output on the terminal (default: the simulator's "
                            "and move_base's; the rest in log files)")
    group.add_argument("--print-launch", action="store_true",
                       help="print the launch file minros sim runs, and exit")
    return parser


#: options of sim_node that minros sim passes on (everything its parser knows but these)
_OWN = {"no_nav", "no_map_server", "web", "screen", "print_launch", "help", "world"}


def node_arguments(parser: argparse.ArgumentParser, args: argparse.Namespace,
                   skip: frozenset = frozenset()) -> List[str]:
    """The sim_node arguments that reproduce ``args`` (options left at their default omitted;
    ``--flag=value`` so that a value starting with "-" stays a value)."""
    out = [args.world]
    for action in parser._actions:  # argparse keeps no public list of its options
        if action.dest in _OWN or action.dest in skip or not action.option_strings:
            continue
        value = getattr(args, action.dest)
        if value == action.default:
            continue
        flag = action.option_strings[-1]
        if isinstance(action, argparse._StoreTrueAction):
            out.append(flag)
        elif isinstance(action, argparse._AppendAction):
            out += [f"{flag}={each}" for each in value]
        else:
            out.append(f"{flag}={value}")
    return out


def launch_xml(args: argparse.Namespace, sim_args: List[str], robots: List[str]) -> str:
    """The launch file: simulator, map_server, a move_base per robot, and minros web."""
    def attr(value: str) -> str:
        return quoteattr(value)

    screen = ' output="screen"'
    lines = ["<launch>"]
    if args.clock:
        lines.append('  <param name="/use_sim_time" value="true"/>')
    lines.append(f'  <node pkg="minros_sim" type="sim_node" name="sim" required="true"{screen}'
                 f" args={attr(' '.join(shlex.quote(a) for a in sim_args))}/>")
    if not args.no_map_server:
        lines.append('  <node pkg="map_server" type="map_server" name="map_server"'
                     f" args={attr(shlex.quote(args.world))}/>")
    if not args.no_nav:
        for name in robots:
            base = f"{name}/base_footprint" if name else "base_footprint"
            node = [f'  <node pkg="move_base" type="move_base" name="move_base"{screen}>',
                    f'    <param name="global_costmap/robot_base_frame" value={attr(base)}/>',
                    '    <remap from="map" to="/map"/>',
                    "  </node>"]
            if name:
                lines.append(f"  <group ns={attr(name)}>")
                lines += ["  " + line for line in node]
                lines.append("  </group>")
            else:
                lines += node
    if args.web is not None:
        lines.append('  <node pkg="rosbridge_server" type="rosbridge_websocket" name="minros_web"'
                     f'{screen}><param name="port" value="{int(args.web)}"/></node>')
    lines.append("</launch>")
    return "\n".join(lines) + "\n"


def main(argv: List[str], prog: str | None = None) -> int:
    from minros.launch.config import LaunchError
    from minros.launch.loader import Loader
    from minros.launch.runner import LaunchRunner
    from minros.nodes.minros_sim.sim_node import make_world
    from minros.rosenv import get_master_uri
    from minros.sim.mapfile import MapError
    from minros.sim.world import WorldError
    from minros.tools.common import strip_ros_args

    prog = prog or "minros sim"
    parser = _parser(prog)
    args = parser.parse_args(strip_ros_args(list(argv)))
    # the nodes run in ROS_HOME, as roslaunch runs them: paths must not depend on the cwd
    args.world = os.path.abspath(args.world)
    if args.snapshot:
        args.snapshot = os.path.abspath(args.snapshot)
    if args.speed != 1.0 and not args.clock:
        args.clock = True  # another speed only makes sense on simulated time
    if args.web is not None and not 0 < args.web < 65536:
        print(f"{prog}: error: --web {args.web} is not a TCP port", file=sys.stderr)
        return 2
    try:
        world = make_world(args)  # fail here, in one line, before anything starts
    except (MapError, WorldError, ValueError) as exc:
        print(f"{prog}: {exc}", file=sys.stderr)
        return 1
    robots = list(world.robots)
    # the simulator gets the robots placed here, so that both sides agree on names and poses
    sim_args = node_arguments(parser, args, skip=frozenset({"robots", "robot"}))
    sim_args += [f"--robot={r.name + '=' if r.name else ''}{r.x!r},{r.y!r},{r.yaw!r}"
                 for r in world.robots.values()]
    text = launch_xml(args, sim_args, robots)
    if args.print_launch:
        sys.stdout.write(text)
        return 0
    try:
        config = Loader().load_string(text, [], "<minros sim>")
        uri = get_master_uri()
        runner = LaunchRunner(config, master_uri=uri if uri.endswith("/") else uri + "/",
                              screen=args.screen)
    except LaunchError as exc:
        print(f"{prog}: error: {exc}", file=sys.stderr)
        return 1
    names = ", ".join(r or "the robot" for r in robots)
    print(f"minros sim: {len(robots)} robot(s) ({names}) on {args.world}"
          + ("" if args.no_nav else "; send goals to move_base (rostopic pub "
             "/move_base_simple/goal ... or actionlib)")
          + (f"; the page at http://localhost:{args.web}/" if args.web is not None else ""),
          flush=True)
    return runner.run()
