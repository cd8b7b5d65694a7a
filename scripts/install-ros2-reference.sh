#!/usr/bin/env bash
# Install the ROS 2 reference the ROS 2 tests and benchmarks run against: real rclpy from PyPI
# (Jazzy, the LTS, and Kilted, both on Fast DDS) with their message wheels, and Eclipse Cyclone
# DDS's Python binding as a second, independent DDS. Each goes into a venv of its own on the
# reference's CPython 3.11 (the wheels are cp311), under $MINROS_ROS2_HOME (default
# /opt/minros-ros2): jazzy/, kilted/, cyclonedds/. Idempotent: a venv whose stamp names the same
# package list is kept. No ROS 2 is installed system-wide and nothing is started.
# See ../shared/spec/ros2.md.
#
#   bash scripts/install-ros2-reference.sh            install what is missing
#   bash scripts/install-ros2-reference.sh --print    print each venv and its packages, and exit
set -euo pipefail
ROOT=${MINROS_ROS2_HOME:-/opt/minros-ros2}
PY=${ROS2_PYTHON:-/usr/bin/python3}

MSGS="std-msgs std-srvs sensor-msgs geometry-msgs nav-msgs visualization-msgs diagnostic-msgs
  shape-msgs stereo-msgs trajectory-msgs actionlib-msgs action-msgs rosgraph-msgs
  builtin-interfaces rcl-interfaces unique-identifier-msgs rmw-dds-common lifecycle-msgs
  type-description-interfaces"
jazzy=("ros-jazzy-rclpy[fastrtps]==7.1.6")
for m in $MSGS; do jazzy+=("ros-jazzy-$m"); done
kilted=("ros-rclpy[fastrtps]==9.1.2")
for m in $MSGS; do kilted+=("ros-$m"); done
cyclone=("cyclonedds==11.0.1")

if [ "${1:-}" = "--print" ]; then
  echo "jazzy: ${jazzy[*]}"; echo "kilted: ${kilted[*]}"; echo "cyclonedds: ${cyclone[*]}"
  exit 0
fi
if ! "$PY" -c 'import sys, ensurepip; assert sys.version_info[:2] == (3, 11)' 2>/dev/null; then
  echo "error: the ROS 2 wheels on PyPI are for CPython 3.11 with venv ($PY is not; install" \
    "python3-venv, or set ROS2_PYTHON to a CPython 3.11)" >&2
  exit 1
fi

build() {  # name packages...
  local name=$1 dir="$ROOT/$1"
  shift
  local want
  want=$(printf '%s\n' "$@")
  if [ -x "$dir/bin/python" ] && [ "$(cat "$dir/.minros-stamp" 2>/dev/null)" = "$want" ]; then
    return 0
  fi
  rm -rf "$dir"
  mkdir -p "$ROOT"
  "$PY" -m venv "$dir"
  # (this image's pip configuration names local indexes that may be absent: their warnings go)
  "$dir/bin/python" -m pip install -q --disable-pip-version-check "$@" 2>&1 | { grep -v "^WARNING: Location" || true; }
  printf '%s\n' "$want" > "$dir/.minros-stamp"
  echo "ROS 2 reference: $name installed in $dir"
}
build jazzy "${jazzy[@]}" &
j=$!
build kilted "${kilted[@]}" &
k=$!
build cyclonedds "${cyclone[@]}"
wait "$j"
wait "$k"
