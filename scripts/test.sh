#!/usr/bin/env bash
# The test command of the README: installs Debian's ROS 1 reference and the ROS 2 reference
# when running as root (or with sudo), builds the venvs, checks ruff, the import contracts and
# the types, then runs the whole suite on the main Python and the unit tests plus the smoke set
# on the other Pythons. Usage: bash scripts/test.sh [pytest args for the main run...]
#
# In order (CI's clock on 2 CPUs in README.md):
#  1. the other Pythons' venvs (pyenv's CPythons need nothing from apt), in the background;
#  2. Debian's ROS 1 reference (apt), then the ROS 2 reference (rclpy from PyPI, in venvs under
#     /opt/minros-ros2, built on /usr/bin/python3, which needs apt's python3-venv) in the
#     background beside the next steps;
#  3. the main venv, ruff, lint-imports, mypy;
#  4. the main run: every test in parallel workers, then the tests marked `timing` alone, then
#     ROS's own rostest suites on minros and on Debian's ROS;
#  5. the other Pythons: tests/unit (but the fuzz tier) and the tests marked `smoke` (a few of
#     each subsystem's), the Pythons side by side, each in one process.
set -euo pipefail
cd "$(dirname "$0")/.."
# Bytecode is cached as Python does by default, even where the machine turned it off: without
# it every process a test starts compiles what it imports again (tests/conftest.py does the
# same for the pytest processes' own imports).
unset PYTHONDONTWRITEBYTECODE
root=
if [ "$(id -u)" -eq 0 ] || sudo -n true 2>/dev/null; then root=1; fi

# -- 1. the other Pythons' venvs, first: every Python the README promises runs the unit tests
# and the smoke set, in a venv of its own. CI requires each; elsewhere a missing one is named
# and skipped. OTHER_PYTHONS= skips them.
find_python() {
  local v=$1 p
  p=$(command -v "python$v" 2>/dev/null) && "$p" -c 'import ensurepip' 2>/dev/null && { echo "$p"; return; }
  for p in "${PYENV_ROOT:-$HOME/.pyenv}"/versions/"$v".*/bin/python"$v"; do
    [ -x "$p" ] && { echo "$p"; return; }
  done
  return 1
}
others=()
for v in ${OTHER_PYTHONS-3.10 3.12 3.13}; do
  if py=$(find_python "$v"); then
    others+=("$v:$py")
  elif [ -n "${CI:-}" ]; then
    echo "error: CI runs the tests on Python $v too, and none was found (install it with pyenv)" >&2
    exit 1
  else
    echo "note: no Python $v found; its run of the unit tests and the smoke set is skipped" >&2
  fi
done
venv_pids=()
for entry in "${others[@]}"; do
  v=${entry%%:*}; py=${entry#*:}
  (
    set -e
    [ -x ".venv-$v/bin/python" ] || "$py" -m venv ".venv-$v"
    ".venv-$v/bin/python" -m pip install -q --upgrade pip
    ".venv-$v/bin/python" -m pip install -q -e '.[test]'
    ".venv-$v/bin/python" -m compileall -q src stubs
  ) > ".venv-$v.log" 2>&1 &
  venv_pids+=("$v:$!")
done
# Foxglove's and roslib's own client libraries for tests/integration/test_web.py
npm_pid=
if command -v npm >/dev/null; then
  (cd tests/web/js && npm ci --no-audit --no-fund --loglevel=error) > .npm-ci.log 2>&1 &
  npm_pid=$!
fi

# -- 2. the references
ros2_pid=
if [ -n "$root" ]; then
  bash scripts/install-ros-reference.sh
  # The ROS 2 tests find their oracle here (../shared/spec/ros2.md); built beside step 3.
  bash scripts/install-ros2-reference.sh > .ros2-reference.log 2>&1 &
  ros2_pid=$!
else
  echo "note: not root, Debian's ROS 1 and the ROS 2 reference not installed; interop tests will skip" >&2
fi

# -- 3. the main venv and the checks. The venv is built on the reference's interpreter when
# there is one, so that benchmarks set minros against rospy on the same Python build; a venv
# never sees Debian's dist-packages, so the two installations stay apart. PYTHON=... picks
# another interpreter.
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
.venv/bin/python -m compileall -q src stubs > /dev/null  # once, not by each process's import
.venv/bin/ruff check src stubs tests benchmarks examples
.venv/bin/lint-imports  # the layers of docs/architecture.md (contracts in pyproject.toml)
.venv/bin/mypy  # the types of the modules [tool.mypy] lists in pyproject.toml
if [ -n "$npm_pid" ] && ! wait "$npm_pid"; then
  cat .npm-ci.log >&2
  echo "error: npm ci in tests/web/js failed" >&2
  exit 1
fi
if [ -n "$ros2_pid" ] && ! wait "$ros2_pid"; then
  cat .ros2-reference.log >&2
  echo "error: scripts/install-ros2-reference.sh failed (the ROS 2 tests' oracle)" >&2
  exit 1
fi

# -- 4. the main run, in parallel workers (pytest-xdist; WORKERS=1 runs it in one process): a
# test spends most of its time waiting on the processes it starts, so four workers on two
# CPUs finish sooner than two. Every test picks free ports and its own ROS_HOME, so workers do
# not meet. A test file stays in one worker (--dist loadfile), in its order, as its
# module-scoped fixtures expect; tests/conftest.py cuts a file of more than 200 tests (the
# parametrized property tests) into units of 200, so that it does not hold one worker while
# the others idle. The tests marked `timing` run afterwards on their own.
workers=${WORKERS:-4}
parallel=()
[ "$workers" -gt 1 ] && parallel=(-n "$workers" --dist loadfile)
# A test that fails in a parallel run is run again alone, once: if it passes alone (passed,
# not skipped), it raced under load and is named as FLAKY, here and again at the end (to be
# fixed: the run passes, the log says which); a test that fails alone too fails the run, and
# so do more than 5 failures (not a race). A run in one process is not rerun.
tmp=$(mktemp -d)
flaky_log=$tmp/flaky
: > "$flaky_log"
trap 'rm -rf "$tmp"' EXIT
run_tests() {  # label python pytest-args...
  local label=$1 py=$2 code=0 failed_list="$tmp/failed-${1//[^a-z0-9.]/_}"
  local rerun_log="$failed_list.rerun"
  shift 2
  : > "$failed_list"
  MINROS_FAILED_LIST=$failed_list "$py" -m pytest "$@" || code=$?
  [ "$code" -eq 0 ] && return 0
  [[ " $* " == *" -n "* ]] || return "$code"
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
status=0
SECONDS=0
if [ "$workers" -gt 1 ]; then
  run_tests "main run" .venv/bin/python "${parallel[@]}" -m "not timing" --durations=30 "$@" || status=$?
  echo "main run: ${SECONDS}s"
  code=0
  .venv/bin/python -m pytest -m timing "$@" || code=$?
  [ "$code" -eq 0 ] || [ "$code" -eq 5 ] || status=$code  # 5: the arguments chose no timing test
  echo "main run and timing tests: ${SECONDS}s"
else
  .venv/bin/python -m pytest "$@" || status=$?
fi

# -- 4b. ROS's own integration tests (ros_comm's registered .test files, each under rostest with a
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

# -- 5. the other Pythons, side by side, each in one process with one worker of its own (two
# CPUs shared by three runs; the fuzz tier, hypothesis's many examples, runs in the main run
# only). A run whose venv did not build fails with the end of its log.
SECONDS=0
run_pids=()
for entry in "${venv_pids[@]}"; do
  v=${entry%%:*}
  if ! wait "${entry#*:}"; then
    echo "Python $v: its venv did not build; the end of .venv-$v.log:" >&2
    tail -n 40 ".venv-$v.log" >&2
    status=1
    continue
  fi
  run_tests "Python $v" ".venv-$v/bin/python" -q -p no:cacheprovider -n 1 \
    -m "not timing and not fuzz and (unit or smoke)" tests >> ".venv-$v.log" 2>&1 &
  run_pids+=("$v:$!")
done
for entry in "${run_pids[@]}"; do
  v=${entry%%:*}
  if wait "${entry#*:}"; then
    echo "Python $v: $(grep -E ' passed| FLAKY' ".venv-$v.log" | tail -n 3)"
  else
    echo "Python $v: unit tests and smoke set FAILED; the end of .venv-$v.log:" >&2
    tail -n 60 ".venv-$v.log" >&2
    status=1
  fi
done
[ "${#run_pids[@]}" -eq 0 ] || echo "other Pythons: ${SECONDS}s"
if [ -s "$flaky_log" ]; then
  echo "Tests that failed in a parallel run and passed alone (races under load, to fix):"
  cat "$flaky_log"
fi
exit $status
