#!/usr/bin/env bash
# Install Debian's ROS 1 (ros_comm 1.15.15, Noetic) for /usr/bin/python3: the reference
# implementation that minros's interoperability tests and benchmarks run against, with the
# Python surface of a full desktop install (ros-desktop-full-python-dev and friends), and the
# tools the tests drive. Idempotent; needs root (CI runs as root).
# See ../shared/spec/ros1-reference.md.
#
# Installs only what is missing: a package already installed is not asked for again, and a
# tool the machine already has from elsewhere is never asked of apt (this image ships Node.js
# from NodeSource, whose nodejs bundles npm and conflicts with Debian's npm package).
#
#   bash scripts/install-ros-reference.sh                   install what is missing
#   bash scripts/install-ros-reference.sh --print-packages  print every apt package this
#       script may install on this machine, one per line, and exit (tests/unit/
#       test_install_script.py simulates installing all of them with apt-get -s)
#   bash scripts/install-ros-reference.sh --sources DIR [SOURCE_PACKAGE ...]
#       fetch Debian's source packages (default: ros-ros-comm, whose tests
#       scripts/rostest_suites.py runs) into DIR and unpack their upstream tarballs there;
#       apt reads a deb-src list of its own under DIR/apt, so the machine's apt setup is
#       neither read for sources nor changed (no root needed; a second run fetches nothing)
set -euo pipefail
if [ "$(id -u)" -ne 0 ]; then SUDO=sudo; else SUDO=; fi

# ROS 1 core, the message packages and the libraries the interop tests compare against.
ROS_CORE="ros-core python3-rosmaster python3-roslaunch rosout
  python3-rospy python3-rostopic python3-rosnode python3-rosparam python3-rosservice
  python3-rosbag python3-roslz4 python3-rosmsg python3-genpy python3-genmsg
  ros-std-msgs python3-std-msgs libstd-msgs-dev ros-std-srvs python3-std-srvs libstd-srvs-dev
  ros-sensor-msgs python3-sensor-msgs libsensor-msgs-dev
  ros-geometry-msgs python3-geometry-msgs libgeometry-msgs-dev
  ros-nav-msgs python3-nav-msgs ros-actionlib-msgs python3-actionlib-msgs
  ros-diagnostic-msgs python3-diagnostic-msgs ros-shape-msgs python3-shape-msgs
  ros-stereo-msgs python3-stereo-msgs ros-trajectory-msgs python3-trajectory-msgs
  ros-visualization-msgs python3-visualization-msgs ros-tf2-msgs python3-tf2-msgs
  ros-roscpp-msg python3-roscpp-msg ros-rosgraph-msgs python3-rosgraph-msgs
  python3-cv-bridge python3-numpy libroscpp-dev g++ pkg-config python3-catkin-pkg
  python3-tf2-ros python3-tf python3-tf2-geometry-msgs tf2-tools tf-tools
  python3-actionlib python3-message-filters python3-diagnostic-updater
  python3-dynamic-reconfigure libdynamic-reconfigure-config-init-mutex-dev
  python3-roslib python3-rosgraph python3-rostest python3-rosunit"
# The Python surface of a full desktop install: what scripts/surface.py compares minros
# against, and the libraries (PyKDL, interactive_markers, ...) the interop tests check.
ROS_DESKTOP_FULL="ros-desktop-full-python-dev python3-pykdl python3-tf2-sensor-msgs
  python3-interactive-markers python3-laser-geometry python3-image-geometry
  python3-tf-conversions python3-tf2-kdl python3-bondpy python3-nodelet python3-topic-tools
  python3-resource-retriever python3-smclib python3-actionlib-tools
  libbond-dev libnodelet-dev libnodeletlib-tools topic-tools
  ros-robot-state-publisher joint-state-publisher joint-state-publisher-gui image-transport-tools
  python3-camera-calibration-parsers python3-map-msgs
  python3-pcl-msgs python3-polled-camera python3-roswtf
  python3-rosclean python3-rosmake python3-rospkg"
# Tools the tests drive besides ROS: a virtual display for turtlesim's window, zsh for
# devel/setup.zsh; python3-venv and python3-tk so that minros's own venv can be built on the
# same interpreter as the reference (scripts/test.sh), turtlesim's Tk window included;
# graphviz for view_frames' frames.pdf; iproute2 for the two-host tests' network namespaces;
# tshark opens the capture files `minros trace pcap` writes.
TEST_TOOLS="xvfb zsh python3-venv python3-tk graphviz iproute2 tshark"

# Debian's sources (--sources): apt with lists, cache and a deb-src entry of its own under DIR/apt.
fetch_sources() {  # dest package...
  local dest=$1 apt_dir codename pkg orig
  shift
  mkdir -p "$dest"
  dest=$(cd "$dest" && pwd)
  apt_dir=$dest/apt
  mkdir -p "$apt_dir/lists/partial" "$apt_dir/cache/archives/partial" "$apt_dir/sources.list.d"
  codename=$(. /etc/os-release 2>/dev/null && echo "${VERSION_CODENAME:-}")
  printf '%s\n' "Types: deb-src" "URIs: http://deb.debian.org/debian" \
    "Suites: ${codename:-bookworm}" "Components: main" \
    "Signed-By: /usr/share/keyrings/debian-archive-keyring.gpg" \
    > "$apt_dir/sources.list.d/debian-src.sources"
  local opts=(-q -o "Dir::Etc::SourceList=/dev/null" -o "Dir::Etc::SourceParts=$apt_dir/sources.list.d"
              -o "Dir::State::Lists=$apt_dir/lists" -o "Dir::Cache=$apt_dir/cache")
  # as root apt hands downloads to its _apt user, who may not enter DIR (under /root)
  [ "$(id -u)" -ne 0 ] || opts+=(-o "APT::Sandbox::User=root")
  if ! ls "$apt_dir/lists/"*_Sources* >/dev/null 2>&1; then
    apt-get "${opts[@]}" update >&2
  fi
  for pkg in "$@"; do
    if ! ls "$dest/${pkg}"_*.orig.tar.* >/dev/null 2>&1; then
      # only the upstream tarball is used: a Debian part that fails to download does not matter
      (cd "$dest" && apt-get "${opts[@]}" source --download-only "$pkg" >&2) ||
        ls "$dest/${pkg}"_*.orig.tar.* >/dev/null 2>&1 ||
        { echo "error: apt-get source $pkg fetched no upstream tarball" >&2; exit 1; }
    fi
    for orig in "$dest/${pkg}"_*.orig.tar.*; do
      tar -xf "$orig" -C "$dest"
    done
    echo "$pkg: unpacked in $dest"
  done
}

if [ "${1:-}" = "--sources" ]; then
  if [ -z "${2:-}" ]; then
    echo "usage: $0 --sources DIR [SOURCE_PACKAGE ...]" >&2
    exit 2
  fi
  dest=$2
  shift 2
  [ "$#" -gt 0 ] || set -- ros-ros-comm
  fetch_sources "$dest" "$@"
  exit 0
fi

# On a machine whose package lists were never fetched, apt knows no package at all.
if ! apt-cache show ros-core >/dev/null 2>&1; then $SUDO apt-get update -q >&2; fi
# A package name is kept only when apt knows it (the archive may drop one); an unknown name
# would make the whole install fail.
KNOWN=$(apt-cache pkgnames)
known() { grep -qxF "$1" <<<"$KNOWN"; }

# Every package this script may install on this machine, one per line.
candidates() {
  local p
  for p in $ROS_CORE $ROS_DESKTOP_FULL $TEST_TOOLS; do
    known "$p" && echo "$p"
  done
  # minros web's tests: Debian's Chromium for roslib in a real browser (Playwright drives
  # it), node and npm for Foxglove's and roslib's own client libraries (tests/web/js). Only
  # asked of apt when the machine has no such command: NodeSource's nodejs carries npm and
  # conflicts with Debian's npm package.
  [ -x /usr/bin/chromium ] || echo chromium
  if ! command -v node >/dev/null; then
    echo nodejs
    command -v npm >/dev/null || echo npm
  elif ! command -v npm >/dev/null; then
    echo "warning: node is installed without npm (and Debian's npm would conflict with a" \
      "NodeSource nodejs); install npm with your Node.js distribution" >&2
  fi
}

installed() {
  [ "$(dpkg-query -W -f='${db:Status-Status}' "$1" 2>/dev/null)" = installed ]
}

if [ "${1:-}" = "--print-packages" ]; then
  candidates
  exit 0
elif [ -n "${1:-}" ]; then
  echo "usage: $0 [--print-packages | --sources DIR [SOURCE_PACKAGE ...]]" >&2
  exit 2
fi

missing=()
while read -r p; do
  installed "$p" || missing+=("$p")
done < <(candidates)
if [ "${#missing[@]}" -eq 0 ]; then
  echo "ROS 1 reference already installed"
  exit 0
fi
echo "installing ${#missing[@]} packages: ${missing[*]}"
$SUDO apt-get update -q
# tshark's package asks whether non-root users may capture: no (and no question)
echo "wireshark-common wireshark-common/install-setuid boolean false" | $SUDO debconf-set-selections
DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y -q --no-install-recommends "${missing[@]}"
/usr/bin/python3 -c 'import rospy, rosmaster, genpy' && echo "ROS 1 reference installed"
