#!/usr/bin/env bash
# The test command of the README: builds the venv, installs minros with its test tools,
# installs Debian's ROS 1 reference when running as root (or with sudo), checks ruff, the
# import contracts and the types, then runs the whole suite. Usage: bash scripts/test.sh [pytest args...]
set -euo pipefail
cd "$(dirname "$0")/.."
if [ "$(id -u)" -eq 0 ] || sudo -n true 2>/dev/null; then
  bash scripts/install-ros-reference.sh
else
  echo "note: not root, Debian's ROS 1 reference not installed; interop tests will skip" >&2
fi
# The venv is built on the reference's interpreter when there is one, so that benchmarks set
# minros against rospy on the same Python build; a venv never sees Debian's dist-packages,
# so the two installations stay apart. PYTHON=... picks another interpreter.
if [ -z "${PYTHON:-}" ] && [ -x /usr/bin/python3 ] && /usr/bin/python3 -c 'import ensurepip' 2>/dev/null; then
  PY=/usr/bin/python3
else
  PY=${PYTHON:-python3}
fi
if [ ! -x .venv/bin/python ]; then
  "$PY" -m venv .venv
fi
.venv/bin/python -m pip install -q --upgrade pip
.venv/bin/python -m pip install -q -e '.[test]'
# Foxglove's and roslib's own client libraries for tests/integration/test_web.py
if command -v npm >/dev/null; then
  (cd tests/web/js && npm ci --no-audit --no-fund --loglevel=error)
fi
.venv/bin/ruff check src stubs tests benchmarks examples
.venv/bin/lint-imports  # the layers of docs/architecture.md (contracts in pyproject.toml)
.venv/bin/mypy  # the types of the modules [tool.mypy] lists in pyproject.toml
.venv/bin/python -m pytest "$@"
