"""Shared test machinery: free ports, ROS environments, process groups, the Debian reference.

Processes are started in their own process group and stopped with SIGINT, then SIGTERM,
then SIGKILL, each step bounded, so a test never leaves a node behind nor hangs CI.
"""

from __future__ import annotations

import functools
import os
import random
import signal
import socket
import subprocess
import sys
import threading
import time
import xmlrpc.client
from pathlib import Path
from typing import Dict, List, Optional, Sequence

import pytest

REPO = Path(__file__).resolve().parent.parent
#: the runnable scripts of examples/, which the example tests run as a user would
EXAMPLES = REPO / "examples"
#: The interpreter that runs minros (the venv's).
PYTHON = sys.executable
#: The system interpreter that sees Debian's ROS 1.
REFERENCE_PYTHON = "/usr/bin/python3"
IN_CI = bool(os.environ.get("CI"))
#: Debian's chromium, the browser the page and web tests drive with Playwright
CHROMIUM = "/usr/bin/chromium"


def need(condition: bool, what: str, installer: str = "scripts/test.sh") -> None:
    """Skip locally, fail in CI, when something a test needs is missing."""
    if condition:
        return
    if IN_CI:
        pytest.fail(f"{what} ({installer} installs it)")
    pytest.skip(what)


def launch_chromium(playwright, *extra_args: str):
    """Debian's chromium, headless and quiet (no background network, updates or sync)."""
    return playwright.chromium.launch(executable_path=CHROMIUM, args=[
        "--headless", "--no-sandbox", "--disable-gpu", "--disable-background-networking",
        "--disable-component-update", "--disable-sync", "--no-first-run", *extra_args])


@functools.cache
def reference_imports(modules: str) -> bool:
    """Whether Debian's interpreter imports ``modules`` ("a, b.c, ...")."""
    if not os.path.exists(REFERENCE_PYTHON):
        return False
    probe = subprocess.run([REFERENCE_PYTHON, "-c", f"import {modules}"], env=reference_env({}),
                           capture_output=True, timeout=60)
    return probe.returncode == 0


def reference_available() -> bool:
    """Whether Debian's ROS 1 (rospy, rosmaster, genpy, tools) is installed."""
    return (reference_imports("rospy, rosmaster, genpy, std_msgs.msg")
            and os.path.exists("/usr/bin/rostopic"))


#: where Debian's python3-*-msgs packages install the classes genpy generated
DEBIAN_DIST_PACKAGES = Path("/usr/lib/python3/dist-packages")


def debian_has_messages(package: str) -> bool:
    """Whether Debian's Python has ``package``'s generated message or service classes (the
    bundled packages Debian lacks are checked against genpy run on the same files instead)."""
    return any((DEBIAN_DIST_PACKAGES / package / kind / "__init__.py").is_file()
               for kind in ("msg", "srv"))


def require_reference() -> None:
    """Skip when the reference is absent locally; in CI its absence is a failure."""
    if reference_available():
        return
    if IN_CI:
        pytest.fail("Debian's ROS 1 reference is not installed (scripts/install-ros-reference.sh)")
    pytest.skip("Debian's ROS 1 reference is not installed")


def require_tf_reference() -> None:
    """Skip when Debian's tf packages are absent locally; in CI their absence is a failure."""
    if reference_imports("tf2_py, tf2_ros, tf.transformations, tf2_geometry_msgs"):
        return
    if IN_CI:
        pytest.fail("Debian's python3-tf2-ros/python3-tf/python3-tf2-geometry-msgs are not "
                    "installed (scripts/install-ros-reference.sh)")
    pytest.skip("Debian's python3-tf2-ros/python3-tf are not installed")


def run_python(code: str, env_extra: Dict[str, str]) -> subprocess.CompletedProcess:
    """``code`` run by minros's interpreter in a fresh process (no PYTHONPATH, plus ``env_extra``)."""
    env = dict(os.environ)
    env.pop("PYTHONPATH", None)
    env.update(env_extra)
    return subprocess.run([PYTHON, "-c", code], capture_output=True, text=True, env=env,
                          timeout=60)


# Ports for test servers come from below the kernel's ephemeral range (32768-60999 on Linux,
# read from /proc): a port the kernel handed out with bind(0) can be taken, before the server
# binds it, by any outgoing connection of any process (seen in CI: "Address already in use"
# under load). Each pytest-xdist worker draws from its own share, so workers never meet either.
_PORT_SHARES = 8
_port_lock = threading.Lock()
_port_next: List[int] = []


@functools.cache  # the kernel's range is read once per process
def _port_range() -> tuple:
    try:
        ephemeral_low = int(Path("/proc/sys/net/ipv4/ip_local_port_range").read_text().split()[0])
    except (OSError, ValueError, IndexError):
        ephemeral_low = 32768
    return 20000, min(32000, ephemeral_low)


def free_port() -> int:
    """A TCP port free on 127.0.0.1 now, not one the kernel gives to outgoing connections."""
    low, high = _port_range()
    span = (high - low) // _PORT_SHARES
    if span < 100:  # an unusual ephemeral range: the kernel's choice, as before
        with socket.socket(socket.AF_INET, socket.SOCK_STREAM) as s:
            s.bind(("127.0.0.1", 0))
            return s.getsockname()[1]
    worker = os.environ.get("PYTEST_XDIST_WORKER", "")  # gw0, gw1, ...
    share = int(worker[2:]) % (_PORT_SHARES - 1) + 1 if worker[2:].isdigit() else 0
    low += share * span
    with _port_lock:
        if not _port_next:  # another run's leftovers are elsewhere
            _port_next.append(random.SystemRandom().randrange(span))
        for _ in range(span):
            port = low + _port_next[0] % span
            _port_next[0] += 1
            with socket.socket(socket.AF_INET, socket.SOCK_STREAM) as s:
                try:
                    s.bind(("127.0.0.1", port))  # no SO_REUSEADDR: a port in TIME_WAIT is skipped
                except OSError:
                    continue
                return port
    raise RuntimeError(f"no free port in {low}..{low + span - 1}")


def ros_env(master_port: Optional[int], home: Path, extra: Optional[Dict[str, str]] = None) -> Dict[str, str]:
    """Environment for a node on loopback talking to the master on ``master_port``."""
    env = dict(os.environ)
    for key in list(env):
        if key.startswith("ROS_") or key == "PYTHONPATH":
            del env[key]
    if master_port is not None:
        env["ROS_MASTER_URI"] = f"http://localhost:{master_port}"
    env["ROS_HOSTNAME"] = "localhost"
    env["ROS_HOME"] = str(home)
    env["ROS_LOG_DIR"] = str(home / "log")
    env["PYTHONUNBUFFERED"] = "1"
    if extra:
        env.update(extra)
    return env


def reference_env(env: Dict[str, str]) -> Dict[str, str]:
    """``env`` made safe for Debian's ROS: no venv on PATH, no PYTHONPATH into minros."""
    out = dict(env) if env else dict(os.environ)
    out.pop("VIRTUAL_ENV", None)
    out.pop("PYTHONPATH", None)
    out.pop("PYTHONHOME", None)
    out["PATH"] = "/usr/bin:/bin:/usr/sbin:/sbin"
    return out


#: lines Debian's tools print because of how the reference machine is set up, not because of
#: what they do: rospkg warns on every package.xml it parses when python3-rosdep is installed
#: but ``rosdep init`` never ran (a full desktop install). Parity tests compare without them.
REFERENCE_NOISE = ("the rosdep view is empty: call 'sudo rosdep init' and 'rosdep update'\n",)


def without_reference_noise(text: str) -> str:
    """``text`` (a Debian tool's stderr) without the lines of :data:`REFERENCE_NOISE`."""
    for line in REFERENCE_NOISE:
        text = text.replace(line, "")
    return text


def rosdep_uninitialised(folder: Path) -> str:
    """A ``rosdep2`` for PYTHONPATH that behaves as an installed rosdep never initialised (its
    view empty), so a test sees the full reference's noise whether or not rosdep is here."""
    package = folder / "rosdep2"
    package.mkdir(parents=True, exist_ok=True)
    (package / "__init__.py").write_text("")
    (package / "rospack.py").write_text(
        "def init_rospack_interface():\n    return object()\n\n\n"
        "def is_view_empty(view):\n    return True\n\n\n"
        "def is_ros_package(view, name):\n    return False\n\n\n"
        "def is_system_dependency(view, name):\n    return False\n")
    return str(folder)


class Proc:
    """A subprocess in its own process group, with bounded, escalating shutdown."""

    def __init__(self, argv: Sequence[str], env: Dict[str, str], cwd: Optional[Path] = None,
                 stdin=subprocess.DEVNULL) -> None:
        self.argv = list(argv)
        self.popen = subprocess.Popen(
            self.argv, env=env, cwd=cwd, stdin=stdin, stdout=subprocess.PIPE,
            stderr=subprocess.STDOUT, start_new_session=True,
        )
        self._output: Optional[str] = None
        self._pending = b""  # read by read_until() but not yet consumed

    @property
    def pid(self) -> int:
        return self.popen.pid

    def alive(self) -> bool:
        return self.popen.poll() is None

    def stop(self, timeout: float = 5.0) -> str:
        """Stop the whole process group (SIGINT, SIGTERM, SIGKILL); return its output."""
        for sig in (signal.SIGINT, signal.SIGTERM, signal.SIGKILL):
            if self.popen.poll() is not None:
                break
            try:
                os.killpg(self.popen.pid, sig)
            except ProcessLookupError:
                break
            try:
                self.popen.wait(timeout)
            except subprocess.TimeoutExpired:
                continue
        try:  # children of the group that outlived the leader
            os.killpg(self.popen.pid, signal.SIGKILL)
        except (ProcessLookupError, PermissionError):
            pass
        return self.output()

    def output(self, timeout: float = 5.0) -> str:
        if self._output is None:
            try:
                out, _ = self.popen.communicate(timeout=timeout)
            except subprocess.TimeoutExpired:
                self.popen.kill()
                out, _ = self.popen.communicate(timeout=timeout)
            self._output = (self._pending + (out or b"")).decode("utf-8", "replace")
            self._pending = b""
        return self._output

    def read_until(self, needle: str, timeout: float) -> str:
        """Read stdout lines until one contains ``needle``; fail after ``timeout`` seconds."""
        import select

        assert self.popen.stdout is not None
        # Read the pipe's file descriptor directly and split lines ourselves: a buffered
        # readline() after select() can swallow several lines at once and then block on the
        # next select() although the needle is already in the buffer.
        fd = self.popen.stdout.fileno()
        seen: List[str] = []
        deadline = time.monotonic() + timeout
        eof = False
        while True:
            while b"\n" in self._pending:
                line, _, self._pending = self._pending.partition(b"\n")
                text = line.decode("utf-8", "replace") + "\n"
                seen.append(text)
                if needle in text:
                    return "".join(seen)
            remaining = deadline - time.monotonic()
            if eof or remaining <= 0:
                break
            ready, _, _ = select.select([fd], [], [], remaining)
            if not ready:
                continue
            chunk = os.read(fd, 65536)
            if chunk:
                self._pending += chunk
            else:
                eof = True
                if self._pending:  # a last line without newline
                    self._pending += b"\n"
        raise AssertionError(
            f"{needle!r} not seen within {timeout}s from {self.argv}; output was:\n{''.join(seen)}")


def wait_for_master(port: int, timeout: float = 15.0) -> None:
    """Block until a master answers getPid on ``port``; fail after ``timeout`` seconds."""
    deadline = time.monotonic() + timeout
    last: Exception = TimeoutError()
    while time.monotonic() < deadline:
        try:
            proxy = xmlrpc.client.ServerProxy(f"http://127.0.0.1:{port}/")
            code, _msg, _pid = proxy.getPid("/test")
            if code == 1:
                return
        except (OSError, xmlrpc.client.Error) as exc:
            last = exc
        time.sleep(0.05)
    raise AssertionError(f"no master answered on port {port} within {timeout}s: {last!r}")


def wait_until(predicate, timeout: float, interval: float = 0.05, what: str = "condition"):
    """Poll ``predicate`` until it returns a truthy value; fail after ``timeout`` seconds."""
    deadline = time.monotonic() + timeout
    while True:
        value = predicate()
        if value:
            return value
        if time.monotonic() >= deadline:
            raise AssertionError(f"{what} not reached within {timeout}s")
        time.sleep(interval)


def build_roscpp(source_text: str, name: str, build_dir: Path, pkgs: Sequence[str] = ("roscpp",),
                 required_headers: Sequence[str] = ()) -> Path:
    """Compile a C++ ROS node with g++ and pkg-config; return the binary.

    Skips locally and fails in CI when the reference's C++ toolchain or headers are missing
    (scripts/install-ros-reference.sh installs them).
    """
    import shutil

    require_reference()

    need(shutil.which("g++") is not None and shutil.which("pkg-config") is not None,
         "g++/pkg-config missing", "scripts/install-ros-reference.sh")
    flags = subprocess.run(["pkg-config", "--cflags", "--libs", *pkgs], capture_output=True,
                           text=True, timeout=30)
    need(flags.returncode == 0 and all(Path(h).exists() for h in required_headers),
         f"roscpp development files missing: {flags.stderr.strip()}",
         "scripts/install-ros-reference.sh")
    source = build_dir / f"{name}.cpp"
    source.write_text(source_text)
    binary = build_dir / name
    compiled = subprocess.run(["g++", "-O2", "-o", str(binary), str(source), *flags.stdout.split()],
                              capture_output=True, text=True, timeout=300)
    assert compiled.returncode == 0, compiled.stderr
    return binary
