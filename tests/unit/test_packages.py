"""minros.packages: the packages minros provides are found and read as on a real install."""

from __future__ import annotations

import pytest

from minros import packages
from minros.workspace.catkin import shipped_python_packages


def _bundled():
    return sorted((p for root in packages.BUILTIN_SHARE_DIRS for p in root.iterdir()
                   if (p / "package.xml").is_file()), key=lambda p: p.name)


@pytest.mark.parametrize("folder", _bundled(), ids=lambda p: p.name)
def test_every_bundled_manifest_reads_as_rospkg_reads_it(folder) -> None:
    """roslib.load_manifest and rospack parse these with catkin_pkg, which refuses what a real
    package.xml could not hold (a maintainer e-mail without a domain, for one)."""
    from catkin_pkg.package import parse_package

    package = parse_package(str(folder / "package.xml"))
    assert package.name == folder.name == packages.manifest_name(folder)
    assert package.version == packages.manifest_version(folder)


#: Python packages minros installs whose name is no ROS package's, as on a real install:
#: PyKDL is the module of the package python_orocos_kdl, urdf_parser_py of urdfdom_py;
#: ament_index_python is ROS 2's (PyPI's xacro looks packages up through it); catkin's
#: package.xml would make CMake users believe minros builds C++ packages
NOT_ROS_PACKAGES = frozenset({"PyKDL", "ament_index_python", "catkin", "urdf_parser_py"})


def test_every_python_package_minros_ships_is_a_ros_package(monkeypatch) -> None:
    """`import rosbag` works, so `rosversion rosbag` and `rospack find rosbag` must too."""
    monkeypatch.delenv("ROS_PACKAGE_PATH", raising=False)
    names = shipped_python_packages()
    assert {"rospy", "roslaunch", "rosbag", "actionlib", "tf"} <= names
    provided = packages.list_packages(refresh=True)
    assert sorted(n for n in names - NOT_ROS_PACKAGES if n not in provided) == []
    assert all(packages.is_builtin(provided[n]) for n in names - NOT_ROS_PACKAGES)
