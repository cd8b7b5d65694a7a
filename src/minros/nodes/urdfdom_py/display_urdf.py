"""rosrun urdfdom_py display_urdf [FILE|-] [-o OUT]: a URDF read with urdf_parser_py and printed
as its object tree (YAML); ``-o`` writes it back as XML. Without FILE the robot comes from the
``robot_description`` parameter."""

from __future__ import annotations

import argparse
import os
import sys
import xml.etree.ElementTree as ET
from typing import List, Optional

import minros
from minros.urdf_parser import xml_reflection
from minros.urdf_parser.urdf import URDF


def main(argv: Optional[List[str]] = None) -> int:
    args_in = sys.argv[1:] if argv is None else list(argv)
    parser = argparse.ArgumentParser(
        prog="display_urdf", description="Load a URDF (urdfdom_py's display_urdf): print the "
        "model, and with -o write it back as XML.")
    parser.add_argument("file", nargs="?", default=None,
                        help="URDF file to load, - for stdin (default: the robot_description "
                             "parameter)")
    parser.add_argument("-o", "--output", metavar="FILE", help="write the model as URDF XML")
    # roslaunch passes __name:= and __log:= to nodes
    args = parser.parse_args([a for a in args_in if not (a.startswith("__") and ":=" in a)])
    where = args.file or "parameter robot_description"
    try:
        if args.file is None:
            robot = URDF.from_parameter_server()
        elif args.file == "-":
            robot = URDF.from_xml_string(sys.stdin.buffer.read())
        else:
            robot = URDF.from_xml_file(args.file)
    except KeyError:
        print("display_urdf: the parameter robot_description is not set: give a URDF file, or "
              "set it (rosparam set robot_description \"$(cat robot.urdf)\")", file=sys.stderr)
        return 1
    except minros.ROSException as exc:  # the master cannot be reached, ...
        print(f"display_urdf: {exc}", file=sys.stderr)
        return 1
    except OSError as exc:
        if args.file is None:
            print(f"display_urdf: cannot reach the master ({exc}): is roscore running?",
                  file=sys.stderr)
        else:
            print(f"display_urdf: cannot read {args.file}: {exc.strerror or exc}", file=sys.stderr)
        return 1
    except ET.ParseError as exc:
        print(f"display_urdf: {where} is not XML: {exc}", file=sys.stderr)
        return 1
    except (xml_reflection.ParseError, ValueError) as exc:
        print(f"display_urdf: {where}: {exc}", file=sys.stderr)
        return 1
    try:
        print(robot, flush=True)
        if args.output == "-":
            print(robot.to_xml_string(), flush=True)
    except BrokenPipeError:  # `display_urdf robot.urdf | head`: the reader went away
        os.dup2(os.open(os.devnull, os.O_WRONLY), sys.stdout.fileno())
        return 0
    if args.output and args.output != "-":
        try:
            with open(args.output, "w", encoding="utf-8") as f:
                f.write(robot.to_xml_string())
        except OSError as exc:
            print(f"display_urdf: cannot write {args.output}: {exc.strerror or exc}", file=sys.stderr)
            return 1
    return 0


if __name__ == "__main__":
    sys.exit(main())
