"""The bundled ROS 2 definitions equal the pip ROS 2's, byte for byte, and say where they
came from (minros.ros2.types.share)."""

from __future__ import annotations

import re
from pathlib import Path

import pytest

from minros.ros2.types.registry import DISTROS, SHARE
from minros.ros2.types.testing import ROS2_HOME
from support import need

#: bundled packages the wheels do not carry (not on PyPI for Jazzy/Kilted)
NOT_IN_WHEELS = {"tf2_msgs", "turtlesim"}
KINDS = ("msg", "srv", "action")


def definitions(root: Path) -> dict:
    return {str(p.relative_to(root)): p for kind in KINDS for p in root.glob(f"*/{kind}/*.{kind}")}


@pytest.mark.parametrize("distro", ["jazzy", "kilted"])
def test_bundled_definitions_equal_the_wheels(distro):
    wheel_share = ROS2_HOME / distro / "share"
    need(wheel_share.is_dir(), f"the pip ROS 2 {distro} is not installed",
         "scripts/install-ros2-reference.sh")
    bundled = definitions(SHARE / distro)
    packages = {rel.split("/")[0] for rel in bundled}
    wheels = {rel: p for rel, p in definitions(wheel_share).items()
              if rel.split("/")[0] in packages}
    assert set(wheels) == {rel for rel in bundled if rel.split("/")[0] not in NOT_IN_WHEELS}
    different = [rel for rel, path in wheels.items() if path.read_bytes() != bundled[rel].read_bytes()]
    assert different == []
    assert len(wheels) > 180


def test_every_package_names_its_source_and_licence():
    for distro in DISTROS:
        sources = (SHARE / distro / "SOURCES.md").read_text()
        for package in sorted(p.name for p in (SHARE / distro).iterdir() if p.is_dir()):
            row = re.search(rf"^\| {package} \| (\S+) \| (\S+) \| `([0-9a-f]{{12}})` \|", sources,
                            re.M)
            assert row, f"{distro}/{package} has no row in SOURCES.md"
            copyright = (SHARE / distro / package / "COPYRIGHT").read_text()
            assert f"https://github.com/{row.group(1)}" in copyright
            assert f"commit {row.group(3)}" in copyright
            licence = re.search(r"its text is \.\./\.\./LICENSES/(\S+)\.$", copyright, re.M)
            assert licence and (SHARE / "LICENSES" / licence.group(1)).is_file()


def test_distros_differ_where_upstream_does():
    jazzy, kilted, humble = (SHARE / d for d in ("jazzy", "kilted", "humble"))
    # comments only, Jazzy's reworded after Kilted branched
    assert (jazzy / "builtin_interfaces/msg/Time.msg").read_bytes() != \
        (kilted / "builtin_interfaces/msg/Time.msg").read_bytes()
    # Humble: 24-byte gids, no service events
    assert "char[24] data" in (humble / "rmw_dds_common/msg/Gid.msg").read_text()
    assert "char[16] data" in (jazzy / "rmw_dds_common/msg/Gid.msg").read_text()
    assert not (humble / "service_msgs").exists()
