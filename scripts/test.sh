#!/usr/bin/env bash
# The test command of the README: builds the venv, installs minros with its test tools,
# installs Debian's ROS 1 reference when running as root (or with sudo), checks ruff,
# then runs the whole suite. Usage: bash scripts/test.sh [pytest args...]
set -euo pipefail
cd "$(dirname "$0")/.."
PY=${PYTHON:-python3}
if [ ! -x .venv/bin/python ]; then
  "$PY" -m venv .venv
fi
.venv/bin/python -m pip install -q --upgrade pip
.venv/bin/python -m pip install -q -e '.[test]'
if [ "$(id -u)" -eq 0 ] || sudo -n true 2>/dev/null; then
  bash scripts/install-ros-reference.sh
else
  echo "note: not root, Debian's ROS 1 reference not installed; interop tests will skip" >&2
fi
.venv/bin/ruff check src tests benchmarks
.venv/bin/python -m pytest "$@"
