#!/usr/bin/env python3
"""How much of Debian's ROS 1 Python surface minros provides.

Lists the Python modules the installed Debian ROS packages put in /usr/lib/python3/dist-packages
(``dpkg -L`` of every installed package built from a ``ros-*`` source package, or from
orocos-kdl for PyKDL: what scripts/install-ros-reference.sh installs for ros-desktop-full),
imports each one under Debian's interpreter and under minros's, and compares the modules and
their public names. Writes a Markdown report (per-package table, missing modules, exclusions
with their reasons) and, on request, the figures as JSON for tests.

Every import runs in a worker subprocess (never in this process: importing arbitrary modules
can have side effects), with stdin, stdout and stderr on /dev/null, a scratch ROS_HOME, a
master URI nothing listens on, and a per-module timeout; a module that hangs or kills its
worker is recorded as such and the next worker carries on after it.

    python3 scripts/surface.py                   writes docs/surface.md
    python3 scripts/surface.py --json out.json   also the figures, machine-readable
"""

from __future__ import annotations

import argparse
import json
import os
import select
import signal
import subprocess
import sys
import tempfile
import time
from collections import defaultdict
from pathlib import Path
from typing import Dict, Iterable, List, Optional, Sequence, Tuple

REPO = Path(__file__).resolve().parent.parent
DIST_PACKAGES = "/usr/lib/python3/dist-packages/"
#: Debian source packages whose binaries make up the ROS surface besides the ``ros-*`` ones
EXTRA_SOURCES = ("orocos-kdl",)

#: Modules left out of the comparison, each with the reason. A key ending in ".*" covers the
#: module and everything under it; other keys are one module.
EXCLUSIONS: Dict[str, str] = {
    "catkin.builder": "catkin's build system (catkin_make_isolated's builder)",
    "catkin.cmake": "catkin's build system (CMake helper paths)",
    "catkin.environment_cache": "catkin's build system (setup file generation)",
    "catkin.init_workspace": "catkin's build system (catkin_init_workspace)",
    "catkin.package_version": "catkin's release tooling (catkin_package_version)",
    "catkin.terminal_color": "catkin's build system (colour output of the builder)",
    "catkin.test_results": "catkin's build system (catkin_test_results)",
    "catkin.tidy_xml": "catkin's build system (test result XML clean-up)",
    "catkin.workspace_vcs": "catkin's build system (VCS queries of the builder)",
    "rosmake.*": "rosbuild's build tool (rosmake), gone since catkin",
    "roscreate.*": "rosbuild's package creation (roscreate-pkg), gone since catkin",
    "rosboost_cfg.*": "rosbuild's Boost flags for C++ builds",
    "gencpp.*": "the C++ message generator, run by catkin at build time",
    "genlisp.*": "the Lisp message generator, run by catkin at build time",
    "genmsg.template_tools": "the empy-template code writer of the C++/Lisp/EusLisp message "
                             "generators, run by catkin at build time",
    "nodelet_topic_tools.*": "parameter configs of C++ nodelets (throttle), no Python API",
    "dynamic_reconfigure.cfg.TestConfig": "config of dynamic_reconfigure's own C++ test node",
    "joint_state_publisher_gui": "a Qt window of sliders (GUI only); the joint_state_publisher "
                                 "module it builds on is there",
    "rviz": "Python bindings (SIP) of rviz's C++/Qt visualizer library",
    "rviz.librviz_sip": "Python bindings (SIP) of rviz's C++/Qt visualizer library",
    "rosdistro.*": "workspace bootstrap tool, not part of a ROS runtime; PyPI has the real one",
    "rosinstall.*": "workspace bootstrap tool, not part of a ROS runtime; PyPI has the real one",
    "rosinstall_generator.*": "workspace bootstrap tool, not part of a ROS runtime; PyPI has the real one",
    "wstool.*": "workspace bootstrap tool, not part of a ROS runtime; PyPI has the real one",
    "vcstools.*": "workspace bootstrap tool, not part of a ROS runtime; PyPI has the real one",
}

# The worker each interpreter runs. argv: a JSON file of jobs [[module, names or null], ...],
# the index to start at, the top-level ROS package names, the pipe to answer on, and folders to
# put first on sys.path (for tests). It answers one JSON line per module: the public names of
# the module (names null) or which of the given names it has. Its stdout and stderr are
# /dev/null, so nothing a module prints can corrupt the answers.
WORKER = r'''
import importlib, json, os, sys, types
out = os.fdopen(int(sys.argv[4]), "w")
jobs = json.load(open(sys.argv[1]))
top = set(json.loads(sys.argv[3]))
sys.path[:0] = json.loads(sys.argv[5])

def public_names(module, name):
    kind = name.rsplit(".", 1)[-1]
    if kind in ("msg", "srv"):
        # a message module's API is its classes (genpy's modules also leak helpers)
        return sorted(n for n in dir(module) if not n.startswith("_")
                      and isinstance(getattr(module, n, None), type))
    declared = getattr(module, "__all__", None)
    if declared is not None:
        return sorted({n for n in declared if isinstance(n, str)})
    names = []
    for n in dir(module):
        if n.startswith("_"):
            continue
        try:
            value = getattr(module, n)
        except Exception:
            continue
        if isinstance(value, types.ModuleType):
            continue
        origin = getattr(value, "__module__", None)
        if isinstance(origin, str):
            base = origin.split(".")[0]
            if base not in top and (base in sys.stdlib_module_names or base in sys.modules):
                continue  # imported from the standard library or a third-party package
        names.append(n)
    return names

for index in range(int(sys.argv[2]), len(jobs)):
    name, wanted = jobs[index]
    out.write(json.dumps({"start": index}) + "\n"); out.flush()
    answer = {"done": index}
    try:
        module = importlib.import_module(name)
    except BaseException as exc:
        answer["error"] = ("%s: %s" % (type(exc).__name__, exc)).splitlines()[0][:300]
    else:
        try:
            if wanted is None:
                answer["names"] = public_names(module, name)
            else:
                answer["has"] = [n for n in wanted if hasattr(module, n)]
        except BaseException as exc:
            answer["error"] = "listing names: %s: %s" % (type(exc).__name__, exc)
    out.write(json.dumps(answer) + "\n"); out.flush()
out.close()
os._exit(0)
'''


def ros_packages() -> List[str]:
    """Installed Debian binary packages built from a ROS source package."""
    listing = subprocess.run(
        ["dpkg-query", "-W", "-f", "${binary:Package}\t${db:Status-Status}\t${source:Package}\n"],
        capture_output=True, text=True, check=True).stdout
    names = []
    for line in listing.splitlines():
        package, status, source = (line.split("\t") + ["", ""])[:3]
        if status == "installed" and (source.startswith("ros-") or source in EXTRA_SOURCES):
            names.append(package.split(":")[0])
    return sorted(set(names))


def module_name(path: str) -> Optional[str]:
    """``pkg.mod`` for a file under dist-packages, None for what is not a public module."""
    if not path.startswith(DIST_PACKAGES):
        return None
    parts = path[len(DIST_PACKAGES):].split("/")
    if parts[-1] == "__init__.py":
        parts = parts[:-1]
    elif parts[-1].endswith(".py") or parts[-1].endswith(".so"):
        parts[-1] = parts[-1].split(".")[0]
    else:
        return None
    if not parts or any(not p.isidentifier() or p.startswith("_") for p in parts):
        return None  # private modules (generated _Type modules, _tf2, ...) and egg-info
    return ".".join(parts)


def debian_modules(packages: Iterable[str]) -> Dict[str, str]:
    """module -> the Debian package installing it."""
    owner: Dict[str, str] = {}
    for package in packages:
        files = subprocess.run(["dpkg", "-L", package], capture_output=True, text=True).stdout
        for path in files.splitlines():
            name = module_name(path)
            if name is not None:
                owner.setdefault(name, package)
    return owner


def exclusion(module: str) -> Optional[str]:
    """The reason ``module`` is excluded, or None."""
    for key, reason in EXCLUSIONS.items():
        if key.endswith(".*"):
            base = key[:-2]
            if module == base or module.startswith(base + "."):
                return reason
        elif module == key:
            return reason
    return None


def clean_env(scratch: Path, python: str) -> Dict[str, str]:
    env = {
        "PATH": f"{Path(python).parent}:/usr/bin:/bin",
        "HOME": str(scratch), "ROS_HOME": str(scratch / "ros"), "ROS_LOG_DIR": str(scratch / "log"),
        "ROS_MASTER_URI": "http://127.0.0.1:9/",  # the discard port: nothing answers
        "LANG": "C.UTF-8", "PYTHONDONTWRITEBYTECODE": "1",
    }
    return env


def run_imports(python: str, jobs: List[Tuple[str, Optional[List[str]]]], top: List[str],
                timeout: float, scratch: Path, sys_path: Sequence[str] = ()) -> Dict[str, dict]:
    """The worker's answer for each job (module, names to look for or None to list them),
    restarting the worker after an import that hangs or ends it."""
    job_file = scratch / f"jobs-{os.getpid()}-{time.monotonic_ns()}.json"
    job_file.write_text(json.dumps(jobs))
    answers: Dict[str, dict] = {}
    start = 0
    while start < len(jobs):
        read_fd, write_fd = os.pipe()
        proc = subprocess.Popen(
            [python, "-I", "-c", WORKER, str(job_file), str(start), json.dumps(top), str(write_fd),
             json.dumps(list(sys_path))],
            stdin=subprocess.DEVNULL, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL,
            pass_fds=(write_fd,), cwd=scratch, env=clean_env(scratch, python),
            start_new_session=True)
        os.close(write_fd)
        current = start
        buffer = b""
        try:
            while True:
                ready, _, _ = select.select([read_fd], [], [], timeout)
                if not ready:
                    answers[jobs[current][0]] = {"error": f"timeout: no answer within {timeout:g} s"}
                    break
                chunk = os.read(read_fd, 65536)
                if not chunk:
                    if current < len(jobs) and jobs[current][0] not in answers:
                        proc.wait(timeout)
                        answers[jobs[current][0]] = {"error": f"the import ended the worker (exit {proc.returncode})"}
                    break
                buffer += chunk
                *lines, buffer = buffer.split(b"\n")
                for line in lines:
                    message = json.loads(line)
                    if "start" in message:
                        current = message["start"]
                    else:
                        answers[jobs[message["done"]][0]] = message
                        current = message["done"] + 1
        finally:
            os.close(read_fd)
            if proc.poll() is None:
                os.killpg(proc.pid, signal.SIGKILL)
            proc.wait()
        start = current + 1 if current < len(jobs) and jobs[current][0] in answers else current
    job_file.unlink()
    return answers


def default_minros_python() -> str:
    venv = REPO / ".venv" / "bin" / "python"
    return str(venv) if venv.exists() else sys.executable


def measure(debian_python: str, minros_python: str, timeout: float) -> dict:
    packages = ros_packages()
    if not packages:
        raise SystemExit("surface: no Debian ROS package is installed "
                         "(bash scripts/install-ros-reference.sh installs them)")
    owner = debian_modules(packages)
    top = sorted({m.split(".")[0] for m in owner})
    modules = sorted(owner)
    with tempfile.TemporaryDirectory(prefix="minros-surface-") as tmp:
        scratch = Path(tmp)
        theirs = run_imports(debian_python, [(m, None) for m in modules], top, timeout, scratch)
        wanted = [(m, theirs[m].get("names", [])) for m in modules]
        ours = run_imports(minros_python, wanted, top, timeout, scratch)
    rows = {}
    for module in modules:
        rows[module] = {
            "package": owner[module],
            "excluded": exclusion(module),
            "debian_error": theirs[module].get("error"),
            "names": theirs[module].get("names", []),
            "minros_error": ours[module].get("error"),
            "has": ours[module].get("has", []),
        }
    return {"packages": packages, "modules": rows}


def figures(data: dict) -> dict:
    """Totals and per-package figures over the counted modules (not excluded, importable
    under Debian)."""
    per_package: Dict[str, dict] = defaultdict(lambda: {"modules": 0, "importable": 0, "names": 0,
                                                        "present": 0, "missing": []})
    for module, row in data["modules"].items():
        if row["excluded"] or row["debian_error"]:
            continue
        entry = per_package[row["package"]]
        entry["modules"] += 1
        entry["names"] += len(row["names"])
        if row["minros_error"]:
            entry["missing"].append(module)
        else:
            entry["importable"] += 1
            entry["present"] += len(row["has"])
    total = {k: sum(p[k] for p in per_package.values())
             for k in ("modules", "importable", "names", "present")}
    total["packages"] = len(per_package)
    return {"total": total, "packages": dict(sorted(per_package.items()))}


def percent(part: int, whole: int) -> str:
    return f"{100.0 * part / whole:.0f}%" if whole else "-"


HISTORY = "## History"


def report(data: dict, numbers: dict, previous: str) -> str:
    total = numbers["total"]
    lines = [
        "# The ROS 1 Python surface minros provides",
        "",
        "*Written by `scripts/surface.py`; do not edit by hand except the History section, "
        "which the script keeps.*",
        "",
        "The Python modules the installed Debian ROS packages put in dist-packages "
        "(`dpkg -L` of every installed binary package built from a `ros-*` source package, or "
        "from orocos-kdl for PyKDL: what `scripts/install-ros-reference.sh` installs for "
        "ros-desktop-full), imported under Debian's `/usr/bin/python3` and under minros. "
        "Private modules (a name component starting with `_`, such as genpy's generated "
        "`_Type` modules) are not counted. A module's public names are its `__all__`, or else "
        "its names without a leading underscore that are not modules nor imported from outside "
        "ROS; for `pkg.msg`/`pkg.srv` they are the message and service classes. A name counts "
        "as present when minros's module has it.",
        "",
        f"**{total['importable']} of {total['modules']} modules importable "
        f"({percent(total['importable'], total['modules'])}); "
        f"{total['present']} of {total['names']} public names present "
        f"({percent(total['present'], total['names'])})**, over {total['packages']} Debian packages.",
        "",
        "| Debian package | modules | importable in minros | public names present | missing modules |",
        "| --- | ---: | ---: | ---: | --- |",
    ]
    for package, entry in numbers["packages"].items():
        missing = ", ".join(f"`{m}`" for m in entry["missing"]) or ""
        lines.append(f"| {package} | {entry['modules']} | {entry['importable']} | "
                     f"{percent(entry['present'], entry['names'])} ({entry['present']}/{entry['names']}) "
                     f"| {missing} |")
    lines += ["", "## Excluded modules", "",
              "Build-time internals and tools outside a ROS runtime; they are not counted.", "",
              "| module | package | reason |", "| --- | --- | --- |"]
    for module, row in data["modules"].items():
        if row["excluded"]:
            lines.append(f"| `{module}` | {row['package']} | {row['excluded']} |")
    broken = [(m, r) for m, r in data["modules"].items() if r["debian_error"] and not r["excluded"]]
    lines += ["", "## Not importable under Debian either", "",
              "Not counted: Debian's own module fails to import in a plain environment.", ""]
    lines += [f"- `{m}` ({r['package']}): {r['debian_error']}" for m, r in broken] or ["(none)"]
    lines += ["", HISTORY, ""]
    lines.append(previous.strip() + "\n" if previous.strip() else "(none yet)\n")
    return "\n".join(lines)


def previous_history(path: Path) -> str:
    try:
        text = path.read_text()
    except OSError:
        return ""
    _, found, rest = text.partition("\n" + HISTORY + "\n")
    return rest if found else ""


def main(argv: Optional[List[str]] = None) -> int:
    parser = argparse.ArgumentParser(
        prog="surface.py", description=__doc__.split("\n\n")[0],
        epilog="Needs Debian's ROS 1 (bash scripts/install-ros-reference.sh) and minros's venv.")
    parser.add_argument("--output", type=Path, default=REPO / "docs" / "surface.md",
                        help="the Markdown report to write (default: docs/surface.md)")
    parser.add_argument("--json", type=Path, help="also write the figures and each module's result as JSON")
    parser.add_argument("--debian-python", default="/usr/bin/python3",
                        help="Debian's interpreter (default: /usr/bin/python3)")
    parser.add_argument("--minros-python", default=default_minros_python(),
                        help="an interpreter that imports minros (default: the repository's .venv)")
    parser.add_argument("--timeout", type=float, default=30.0,
                        help="seconds one import may take before it counts as hung (default: 30)")
    args = parser.parse_args(argv)
    for python in (args.debian_python, args.minros_python):
        if not os.access(python, os.X_OK):
            parser.error(f"{python} is not an executable interpreter")
    data = measure(args.debian_python, args.minros_python, args.timeout)
    numbers = figures(data)
    args.output.parent.mkdir(parents=True, exist_ok=True)
    args.output.write_text(report(data, numbers, previous_history(args.output)))
    if args.json:
        args.json.write_text(json.dumps({"figures": numbers, "modules": data["modules"]}, indent=1))
    total = numbers["total"]
    print(f"{total['importable']}/{total['modules']} modules importable, "
          f"{total['present']}/{total['names']} public names present "
          f"({percent(total['present'], total['names'])}); report: {args.output}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
