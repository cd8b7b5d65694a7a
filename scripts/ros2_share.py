#!/usr/bin/env python3
"""Write minros's bundled ROS 2 interface definitions (src/minros/ros2/types/share/) from
checkouts of their upstream repositories, verbatim, with where each file came from.

    python scripts/ros2_share.py MIRRORS [--wheels /opt/minros-ros2]

MIRRORS holds bare clones named ``owner+name/repo`` (what the session tools' ``fetch`` brings:
ros2/common_interfaces, ros2/rcl_interfaces, ros2/rmw_dds_common, ros2/unique_identifier_msgs,
ros2/geometry2, ros/ros_tutorials). Each distro takes each package at the commit named below.
A few files are newer than the clones available when this was written: those are taken from the
released pip wheels of that distro (built by ros-python-wheels from upstream's release tags) and
SOURCES.md says so file by file. tests/unit/test_ros2_types_share.py checks every bundled file
against the installed wheels byte for byte.
"""

from __future__ import annotations

import argparse
import hashlib
import shutil
import subprocess
import sys
from pathlib import Path

SHARE = Path(__file__).resolve().parent.parent / "src" / "minros" / "ros2" / "types" / "share"

COMMON = ["actionlib_msgs", "diagnostic_msgs", "geometry_msgs", "nav_msgs", "sensor_msgs",
          "shape_msgs", "std_msgs", "std_srvs", "stereo_msgs", "trajectory_msgs",
          "visualization_msgs"]
RCL = ["action_msgs", "builtin_interfaces", "lifecycle_msgs", "rcl_interfaces", "rosgraph_msgs",
       "service_msgs", "type_description_interfaces"]

#: repository -> (packages, {package: folder in the repository}, licence id, licence file)
REPOS = {
    "ros2/common_interfaces": (COMMON, {}, "Apache-2.0", "{pkg}/LICENSE"),
    "ros2/rcl_interfaces": (RCL, {}, "Apache-2.0", "LICENSE"),
    "ros2/rmw_dds_common": (["rmw_dds_common"], {}, "Apache-2.0", "LICENSE"),
    "ros2/unique_identifier_msgs": (["unique_identifier_msgs"], {"unique_identifier_msgs": ""},
                                    "BSD-3-Clause", "LICENSE"),
    "ros2/geometry2": (["tf2_msgs"], {}, "BSD-3-Clause", "LICENSE"),
    # no LICENSE file: package.xml says BSD, the sources carry Willow Garage's BSD text
    "ros/ros_tutorials": (["turtlesim"], {}, "BSD-3-Clause", None),
}

#: distro -> repository -> (branch, commit, version of the packages at that commit)
COMMITS = {
    "jazzy": {
        "ros2/common_interfaces": ("jazzy", "5283bd97b33584eb2246fc6134b2e948027e1c3c", "5.3.5"),
        "ros2/rcl_interfaces": ("jazzy", "003987ecb81a32802ab27dd6d325b8c6b8b813cc", "2.0.2"),
        "ros2/rmw_dds_common": ("jazzy", "973ad5c8b60140dbdafe80eb8a192f1d913f94f6", "3.1.0"),
        "ros2/unique_identifier_msgs": ("jazzy", "ced22ce6e0d197357b27157f35107f5b7173b272",
                                        "2.5.0"),
        "ros2/geometry2": ("jazzy", "646342c6164e837d69460e3d28e7a025396544f6", "0.36.4"),
        # ros_tutorials had no jazzy branch in the clone; Jazzy's turtlesim 1.8.x is rolling's
        "ros/ros_tutorials": ("rolling", "9481d9a4f09d923cc972d017c6acc0e61fa9d7bb", "1.8.2"),
    },
    # Kilted branched from rolling in 2025; the clones end at rolling's state of late 2024,
    # whose definitions equal Kilted's released ones (checked against the wheels) but one
    "kilted": {
        "ros2/common_interfaces": ("rolling", "c0c0bc57f958eb54a142446f0c2a475754367eee", "5.4.2"),
        "ros2/rcl_interfaces": ("rolling", "f6b3741d921ef5414125091b2ccc74b863be3c24", "2.2.0"),
        "ros2/rmw_dds_common": ("rolling", "0cf1ce476af39f8706004ea5432d00645aa93a66", "3.2.0"),
        "ros2/unique_identifier_msgs": ("rolling", "0d6c41ef5fc060f8dac7aae5dbad93692826b9e6",
                                        "2.7.0"),
        "ros2/geometry2": ("rolling", "1b005c6556cf350d7670812ef30eefed8443a759", "0.39.1"),
        "ros/ros_tutorials": ("rolling", "9481d9a4f09d923cc972d017c6acc0e61fa9d7bb", "1.8.2"),
    },
    "humble": {
        "ros2/common_interfaces": ("humble", "53761cba9a000902602e7e695cb40de78eadee7f", "4.2.4"),
        "ros2/rcl_interfaces": ("humble", "5e01a28f9866a564491480e12d8659a134678741", "1.2.1"),
        "ros2/rmw_dds_common": ("humble", "e26ba1079886c5598614172db0b27526aa6af07d", "1.6.0"),
        "ros2/unique_identifier_msgs": ("humble", "27767cefcf8a80da44641dc208c57722c28aa11c",
                                        "2.2.1"),
        "ros2/geometry2": ("humble", "d0dbd516d1748cfe1b293e0f7d5b2f82ddd3438a", "0.25.8"),
        "ros/ros_tutorials": ("humble", "ba29c3f376197e3736f497639299f855cbf73390", "1.4.2"),
    },
}

#: distro -> files newer than the clones: (package-relative path, wheel it is taken from, note)
FROM_WHEELS = {
    "jazzy": [
        ("nav_msgs/msg/Goals.msg", "ros-jazzy-nav-msgs 5.3.6",
         "added after the clone; upstream commit 3ad2c9222ba64679d15ab4a0f896faa9c0ac0260 "
         "(GitHub code index) has the same text"),
        ("builtin_interfaces/msg/Time.msg", "ros-jazzy-builtin-interfaces 2.0.3",
         "comments reworded on the jazzy branch after the clone"),
        ("builtin_interfaces/msg/Duration.msg", "ros-jazzy-builtin-interfaces 2.0.3",
         "comments reworded on the jazzy branch after the clone"),
    ],
    "kilted": [
        ("nav_msgs/msg/Goals.msg", "ros-nav-msgs 5.5.1",
         "added after the clone; upstream commit 3ad2c9222ba64679d15ab4a0f896faa9c0ac0260 "
         "(GitHub code index) has the same text"),
    ],
    "humble": [],
}

#: ros1_bridge mapping rules the packages ship (interface data too)
RULE_FILES = {"rcl_interfaces": "mapping_rules.yaml",
              "unique_identifier_msgs": "mapping_rules.yaml",
              "tf2_msgs": "tfmessage_bridge_mapping_rule.yaml"}

TURTLESIM_LICENCE = "src/turtle_frame.cpp"


def git(mirror: Path, *args: str) -> bytes:
    return subprocess.run(["git", "-C", str(mirror), *args], check=True,
                          capture_output=True).stdout


def bsd_from_header(text: str) -> str:
    """The licence comment at the top of a C++ file, without its ``//`` markers."""
    lines = []
    for line in text.splitlines():
        if not line.startswith("//"):
            break
        lines.append(line[2:].removeprefix(" "))
    return "\n".join(lines).strip() + "\n"


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("mirrors", type=Path)
    parser.add_argument("--wheels", type=Path, default=Path("/opt/minros-ros2"))
    args = parser.parse_args()
    if SHARE.exists():
        shutil.rmtree(SHARE)
    licences: dict[str, str] = {}  # text digest -> file name under share/LICENSES
    (SHARE / "LICENSES").mkdir(parents=True)
    for distro, repos in COMMITS.items():
        rows = []
        wheel_files = {path for path, _w, _n in FROM_WHEELS[distro]}
        for repo, (branch, commit, version) in repos.items():
            packages, folders, licence_id, licence_path = REPOS[repo]
            mirror = args.mirrors / repo.replace("/", "+") / "repo"
            for pkg in packages:
                folder = folders.get(pkg, pkg)
                if licence_path is None:
                    text = bsd_from_header(git(mirror, "show", f"{commit}:{folder}/"
                                               f"{TURTLESIM_LICENCE}").decode())
                else:
                    try:
                        text = git(mirror, "show", f"{commit}:{licence_path.format(pkg=pkg)}")
                    except subprocess.CalledProcessError:  # humble: one for the repository
                        text = git(mirror, "show", f"{commit}:LICENSE")
                    text = text.decode()
                digest = hashlib.sha256(text.encode()).hexdigest()[:8]
                name = licences.setdefault(digest, f"{licence_id}.txt" if licence_id == "Apache-2.0"
                                           else f"{licence_id}.{repo.split('/')[1]}.txt")
                (SHARE / "LICENSES" / name).write_text(text)
                prefix = f"{folder}/" if folder else ""
                listing = git(mirror, "ls-tree", "-r", "--name-only", commit, "--", prefix or ".")
                count = 0
                for path in listing.decode().splitlines():
                    rel = path[len(prefix):]
                    kind, _, leaf = rel.partition("/")
                    wanted = (kind in ("msg", "srv", "action") and "/" not in leaf
                              and leaf.endswith("." + kind)) or rel == RULE_FILES.get(pkg)
                    if not wanted or f"{pkg}/{rel}" in wheel_files:
                        continue
                    target = SHARE / distro / pkg / rel
                    target.parent.mkdir(parents=True, exist_ok=True)
                    target.write_bytes(git(mirror, "show", f"{commit}:{path}"))
                    count += 1
                if count == 0 and not any(p.startswith(pkg + "/") for p in wheel_files):
                    continue  # not in this distro (Humble has no service_msgs)
                (SHARE / distro / pkg).mkdir(parents=True, exist_ok=True)
                (SHARE / distro / pkg / "COPYRIGHT").write_text(
                    f"The interface definitions in this folder are taken verbatim from "
                    f"https://github.com/{repo}\n(branch {branch}, commit {commit}, "
                    f"package version {version})"
                    + "".join(f",\nexcept {p.partition('/')[2]}: from the {w} wheel ({n})"
                              for p, w, n in FROM_WHEELS[distro] if p.startswith(pkg + "/"))
                    + f".\nLicence: {licence_id}; its text is ../../LICENSES/{name}.\n")
                rows.append(f"| {pkg} | {repo} | {branch} | `{commit[:12]}` | {version} | "
                            f"{licence_id} | {count} |")
        for path, _wheel, _note in FROM_WHEELS[distro]:
            source = args.wheels / distro / "share" / path
            target = SHARE / distro / path
            target.parent.mkdir(parents=True, exist_ok=True)
            shutil.copyfile(source, target)
        (SHARE / distro / "SOURCES.md").write_text(
            f"# ROS 2 {distro.capitalize()}: where these interface definitions come from\n\n"
            "Written by scripts/ros2_share.py; every file verbatim. Files: msg/srv/action\n"
            "definitions and ros1_bridge mapping rules taken from the commit.\n\n"
            "| package | repository | branch | commit | version | licence | files |\n"
            "|---|---|---|---|---|---|---|\n" + "\n".join(rows) + "\n"
            + ("\nTaken from the released wheels instead (newer than the clones):\n\n"
               + "".join(f"- `{p}`: {w}; {n}\n" for p, w, n in FROM_WHEELS[distro])
               if FROM_WHEELS[distro] else ""))
    print(f"wrote {SHARE}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
