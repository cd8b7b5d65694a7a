"""``minros pkg`` / ``rospack``: find and list ROS packages.

Output follows rospack: ``find`` prints the package folder, ``list`` prints ``name path`` lines
sorted by name, ``list-names`` only the names. An unknown package is one line on stderr.
"""

from __future__ import annotations

import argparse
import sys
from typing import List

from minros import packages


def _parser(prog: str) -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(prog=prog, description="Find and list ROS packages.")
    sub = parser.add_subparsers(dest="command", metavar="COMMAND")
    find = sub.add_parser("find", help="print the folder of a package")
    find.add_argument("package")
    sub.add_parser("list", help="print 'name path' of every package")
    sub.add_parser("list-names", help="print the name of every package")
    depends = sub.add_parser("depends1", help="print the direct dependencies of a package")
    depends.add_argument("package")
    return parser


def main(argv: List[str], prog: str | None = None) -> int:
    parser = _parser(prog or "minros pkg")
    args = parser.parse_args(argv)
    if args.command is None:
        parser.print_help()
        return 0
    if args.command in ("find", "depends1"):
        path = packages.find_package(args.package)
        if path is None:
            print(f"[rospack] Error: package '{args.package}' not found", file=sys.stderr)
            return 1
        if args.command == "find":
            print(path)
        else:
            from minros.workspace.catkin import read_manifest

            for dep in read_manifest(path).run_depends:
                print(dep)
        return 0
    found = packages.list_packages(refresh=True)
    for name in sorted(found):
        print(name if args.command == "list-names" else f"{name} {found[name]}")
    return 0
