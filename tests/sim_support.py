"""Test helpers for ``minros sim``: a running simulator and the probe every client runs.

The probe (tests/integration/sim_probe.py) and the watcher (sim_watch.py) are plain rospy
scripts: they run unchanged on minros and on Debian's rospy and tf2_ros.
"""

from __future__ import annotations

import json
import math
import subprocess
import time
from pathlib import Path

import pytest

from support import EXAMPLES, PYTHON, REFERENCE_PYTHON, Proc, free_port, reference_env, ros_env

HERE = Path(__file__).resolve().parent / "integration"
PROBE = str(HERE / "sim_probe.py")
WATCH = str(HERE / "sim_watch.py")
SEND_GOAL = str(EXAMPLES / "sim" / "send_goal.py")
READY = "(minros's teaching version) is ready"


class Sim:
    """A running ``minros sim`` and the environment its clients use."""

    def __init__(self, home: Path, *args: str, env_extra: dict | None = None,
                 port: int | None = None, wait_for: tuple = ()) -> None:
        self.port = port or free_port()
        self.home = home
        self.env = ros_env(self.port, home, env_extra)
        self.proc = Proc([PYTHON, "-m", "minros", "sim", *args], self.env)
        self.startup = ""
        # the nodes start in parallel: their lines come in any order
        wanted = list(wait_for or ("Hz steps", READY))
        deadline = time.monotonic() + 45
        try:
            while any(self.startup.count(n) < wanted.count(n) for n in wanted):
                self.startup += self.proc.read_until(
                    "\n", timeout=max(0.1, deadline - time.monotonic()))
        except BaseException:
            # no fixture will stop a simulator that never came up: stop it here
            rest = self.proc.stop(timeout=10)
            raise AssertionError(f"minros sim did not start: waited for {wanted}; output:\n"
                                 f"{self.startup}{rest}") from None

    def run(self, argv, timeout: float = 60, env: dict | None = None,
            ns: str = "") -> subprocess.CompletedProcess:
        run_env = dict(env or self.env)
        if ns:
            run_env["ROS_NAMESPACE"] = ns
        return subprocess.run(argv, env=run_env, capture_output=True, text=True, timeout=timeout)

    def python(self, *args: str, timeout: float = 60, ns: str = "") -> subprocess.CompletedProcess:
        return self.run([PYTHON, *args], timeout=timeout, ns=ns)

    def debian(self, *args: str, timeout: float = 60, ns: str = "") -> subprocess.CompletedProcess:
        """A script run by Debian's Python, with Debian's rospy."""
        return self.run([REFERENCE_PYTHON, *args], timeout=timeout, env=reference_env(self.env),
                        ns=ns)

    def tool(self, *args: str, timeout: float = 30) -> subprocess.CompletedProcess:
        return self.run([PYTHON, "-m", "minros", *args], timeout=timeout)

    def ground_truth(self, ns: str = "") -> tuple:
        prefix = f"/{ns}" if ns else ""
        out = self.tool("topic", "echo", "-n", "1", f"{prefix}/base_pose_ground_truth/pose/pose/position")
        values = dict(line.split(": ") for line in out.stdout.splitlines() if ": " in line)
        return float(values["x"]), float(values["y"])

    def reset(self) -> None:
        assert self.tool("service", "call", "/reset_positions").returncode == 0

    def stop(self) -> str:
        return self.proc.stop(timeout=10)


def probe(sim: Sim, ns: str = "", python: str = PYTHON, env: dict | None = None) -> dict:
    result = sim.run([python, PROBE, ns], timeout=60, env=env)
    assert result.returncode == 0, result.stdout + result.stderr
    return json.loads(result.stdout.strip().splitlines()[-1])


def check_probe(seen: dict, prefix: str = "") -> None:
    scan = seen["scan"]
    assert scan["beams"] == 360 and scan["frame"] == prefix + "base_scan"
    assert scan["angle_min"] == 0.0
    assert scan["angle_increment"] == pytest.approx(2 * math.pi / 360)
    assert (scan["range_min"], scan["range_max"]) == pytest.approx((0.12, 3.5))
    assert seen["odom"] == {"frame": prefix + "odom", "child": prefix + "base_footprint"}
    assert seen["odom_chain"] == prefix + "odom->" + prefix + "base_footprint"
    grid = seen["map"]
    assert (grid["width"], grid["height"], grid["frame"]) == (200, 160, "map")
    assert grid["resolution"] == pytest.approx(0.05) and grid["occupied"] > 1000
    assert grid["served_equal"]
    assert seen["urdf"]
