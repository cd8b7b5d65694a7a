#!/usr/bin/env bash
# The test command of the README: builds the venv, installs minros with its test tools,
# installs Debian's ROS 1 reference when running as root (or with sudo), checks ruff, the
# import contracts and the types, then runs the whole suite. Usage: bash scripts/test.sh [pytest args...]
set -euo pipefail
cd "$(dirname "$0")/.."
if [ "$(id -u)" -eq 0 ] || sudo -n true 2>/dev/null; then
  bash scripts/install-ros-reference.sh
  bash scripts/install-ros2-reference.sh  # the pip ROS 2 (rclpy Jazzy, Kilted) the ROS 2 tests use
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

# Every Python the README promises: the unit and integration tests also run on the oldest and
# the newest CPython (pyenv's, on this project's image), in venvs of their own. Their venvs are
# built while the main run goes; their tests run after it, one Python at a time, each with the
# machine to itself (run beside the main one at a low priority, they starved and timed out).
# CI requires both; elsewhere a missing one is named and skipped. OTHER_PYTHONS= skips them.
find_python() {
  local v=$1 p
  p=$(command -v "python$v" 2>/dev/null) && "$p" -c 'import ensurepip' 2>/dev/null && { echo "$p"; return; }
  for p in "${PYENV_ROOT:-$HOME/.pyenv}"/versions/"$v".*/bin/python"$v"; do
    [ -x "$p" ] && { echo "$p"; return; }
  done
  return 1
}
others=()
for v in ${OTHER_PYTHONS-3.10 3.13}; do
  if py=$(find_python "$v"); then
    others+=("$v:$py")
  elif [ -n "${CI:-}" ]; then
    echo "error: CI runs the tests on Python $v too, and none was found (install it with pyenv)" >&2
    exit 1
  else
    echo "note: no Python $v found; its run of the unit and integration tests is skipped" >&2
  fi
done
pids=()
for entry in "${others[@]}"; do
  v=${entry%%:*}; py=${entry#*:}
  (
    set -e
    [ -x ".venv-$v/bin/python" ] || "$py" -m venv ".venv-$v"
    ".venv-$v/bin/python" -m pip install -q --upgrade pip
    nice -n 19 ".venv-$v/bin/python" -m pip install -q -e '.[test]'
  ) > ".venv-$v.log" 2>&1 &
  pids+=("$v:$!")
done
status=0
# The runs in parallel workers (pytest-xdist; WORKERS=1 runs each in one process): a test
# spends most of its time waiting on the processes it starts, so three workers on two CPUs
# finish far sooner than one. Every test picks free ports and its own ROS_HOME, so workers do
# not meet; a test file stays in one worker (--dist loadfile), in its order, as its
# module-scoped fixtures expect. The tests marked `timing` run afterwards on their own.
workers=${WORKERS:-3}
parallel=()
[ "$workers" -gt 1 ] && parallel=(-n "$workers" --dist loadfile)
# A test that fails in a parallel run is run again alone, once: if it passes alone (passed,
# not skipped), it raced under load and is named as FLAKY, here and again at the end (to be
# fixed: the run passes, the log says which); a test that fails alone too fails the run, and
# so do more than 5 failures (not a race). A run in one process is not rerun.
failed_list=$(mktemp)
flaky_log=$(mktemp)
rerun_log=$(mktemp)
trap 'rm -f "$failed_list" "$flaky_log" "$rerun_log"' EXIT
run_tests() {  # label python pytest-args...
  local label=$1 py=$2 code=0
  shift 2
  : > "$failed_list"
  MINROS_FAILED_LIST=$failed_list "$py" -m pytest "$@" || code=$?
  [ "$code" -eq 0 ] && return 0
  [ "${#parallel[@]}" -gt 0 ] || return "$code"
  local count
  count=$(wc -l < "$failed_list")
  if [ "$code" -eq 1 ] && [ "$count" -ge 1 ] && [ "$count" -le 5 ]; then
    local ids
    mapfile -t ids < "$failed_list"
    echo "$label: $count test(s) failed in the parallel run; running them again alone:"
    "$py" -m pytest -q -p no:cacheprovider "${ids[@]}" > "$rerun_log" 2>&1 || true
    cat "$rerun_log"
    if tail -n 1 "$rerun_log" | grep -Eq "^(=+ )?$count passed(, [0-9]+ warnings?)? in "; then
      echo "$label: FLAKY (failed in the parallel run, passed alone): ${ids[*]}" | tee -a "$flaky_log"
      return 0
    fi
  fi
  return "$code"
}
if [ "$workers" -gt 1 ]; then
  run_tests "main run" .venv/bin/python "${parallel[@]}" -m "not timing" --durations=30 "$@" || status=$?
  code=0
  .venv/bin/python -m pytest -m timing "$@" || code=$?
  [ "$code" -eq 0 ] || [ "$code" -eq 5 ] || status=$code  # 5: the arguments chose no timing test
else
  .venv/bin/python -m pytest "$@" || status=$?
fi
# ROS's own integration tests (ros_comm's registered .test files, each under rostest with a
# master of its own) on minros and on Debian's ROS side by side, from Debian's source package
# (scripts/install-ros-reference.sh --sources): fails when minros passes fewer tests than
# Debian in a suite. 68 rostest runs, 4 at a time: about 4 minutes. ROSTEST_SUITES=0 skips it.
run_rostest_suites() {
  [ "${ROSTEST_SUITES:-1}" != 0 ] || return 0
  if [ ! -x /usr/bin/rostest ]; then
    if [ -n "${CI:-}" ]; then
      echo "error: CI runs ROS's rostest suites against Debian's ROS, which is not installed" >&2
      return 1
    fi
    echo "note: Debian's ROS 1 is not installed; ROS's rostest suites are skipped" >&2
    return 0
  fi
  .venv/bin/python scripts/rostest_suites.py --check
}
run_rostest_suites || status=1
for entry in "${pids[@]}"; do
  v=${entry%%:*}
  if wait "${entry#*:}" && run_tests "Python $v" ".venv-$v/bin/python" -q -p no:cacheprovider \
      "${parallel[@]}" -m "not interop and not timing" tests/unit tests/integration \
      >> ".venv-$v.log" 2>&1; then
    echo "Python $v: $(grep -E ' passed| FLAKY' ".venv-$v.log" | tail -n 3)"
  else
    echo "Python $v: unit and integration tests FAILED; the end of .venv-$v.log:" >&2
    tail -n 60 ".venv-$v.log" >&2
    status=1
  fi
done
if [ -s "$flaky_log" ]; then
  echo "Tests that failed in a parallel run and passed alone (races under load, to fix):"
  cat "$flaky_log"
fi
exit $status
