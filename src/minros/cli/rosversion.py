"""``minros version`` / ``rosversion``: the version of a ROS package, or the distribution name.

As rospkg's ``rosversion``: ``rosversion PKG`` prints the ``<version>`` of the package's
``package.xml`` (``<unversioned>`` without one; ``Cannot locate [PKG]`` on stdout and status 1
for an unknown package), ``-d`` the distribution (ROS_DISTRO, else ``noetic``: minros speaks
Noetic's protocols), ``-a`` every package with its version, ``-s`` leaves out the newline.
Packages are the ones ``rospack`` sees: ROS_PACKAGE_PATH, then the ones minros provides
(rospy, roslaunch, rosbag, ... with Debian's versions), so roscore.xml's
``rosversion roslaunch`` works whichever ``roscore`` runs it.
"""

from __future__ import annotations

import argparse
import os
import sys
from typing import List

from minros import packages

#: minros implements the Noetic protocols; tools that ask for the distro get a real one.
ROSDISTRO = "noetic"


def _parser(prog: str) -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(
        prog=prog, formatter_class=argparse.RawTextHelpFormatter,
        description="rosversion package: Output the version of the given package\n"
                    "rosversion -d: Output the ROS distribution name")
    parser.add_argument("-s", "--skip-newline", action="store_true", help="Skip trailing newline")
    group = parser.add_mutually_exclusive_group(required=True)
    group.add_argument("package", nargs="?", help="The ROS package name (e.g. 'roscpp')")
    group.add_argument("-d", "--distro", action="store_true", help="Output the ROS distribution name")
    group.add_argument("-a", "--all", action="store_true",
                       help="Show all ROS package names and their versions")
    return parser


def version_of(package: str) -> str | None:
    """The version of ``package`` (``<unversioned>`` without one), or None when it is unknown."""
    folder = packages.find_package(package)
    if folder is None:
        return None
    return packages.manifest_version(folder) or "<unversioned>"


def main(argv: List[str], prog: str = "rosversion") -> int:
    args = _parser(prog).parse_args(argv)
    end = "" if args.skip_newline else "\n"
    if args.distro:
        sys.stdout.write((os.environ.get("ROS_DISTRO") or ROSDISTRO) + end)
        return 0
    if args.all:
        found = packages.list_packages(refresh=True)
        for name in sorted(found):
            sys.stdout.write(f"{name}: {packages.manifest_version(found[name]) or '<unversioned>'}{end}")
        return 0
    version = version_of(args.package)
    if version is None:
        print(f"Cannot locate [{args.package}]")
        return 1
    sys.stdout.write(version + end)
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
