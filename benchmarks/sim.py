#!/usr/bin/env python3
"""minros sim benchmark: is the 2D simulator faster than real time for 5 robots at 10 Hz laser?

    .venv/bin/python benchmarks/sim.py [--rounds 3] [--seconds 8]

Two parts, contenders interleaved round by round (median of the rounds shown):

* **the world, in process**: one simulated second of 5 TurtleBot3 robots (30 steps and 10
  scans of 5 x 360 beams, range 3.5 m) on the default world (10 m x 8 m at 5 cm) and on a
  cluttered 20 m x 20 m world (400 x 400 cells, 3 % random walls). The ray casters compared:
  minros's (ray marching over a distance field, numpy), uniform sampling every half cell
  (numpy, the simplest vectorised caster), and a grid traversal ray by ray in pure Python
  (what one writes without numpy). Columns: CPU milliseconds per 5-robot scan, and the
  real-time factor of the whole simulated second (simulated seconds per second of CPU), both
  in CPU time so that other processes on a shared machine do not count;
* **the node, end to end**: ``sim_node --robots 5 --laser-rate 10 --clock`` publishing
  every scan, odometry and tf to a subscriber process that takes them all, run as fast as it
  can (``--speed 0``): the real-time factor read off ``/clock``, with the scans received per
  simulated second (50 expected), and the simulated seconds per second of the simulator's own
  CPU (what one free core would give). The same node code runs on minros and on Debian's rospy
  (/usr/bin/python3, ``src/`` on its path but not ``stubs/``); then at ``--speed 1``, the CPU
  the simulator takes (% of one core). These are wall-clock figures: on a loaded machine
  (``/proc/loadavg`` is printed) the as-fast-as-possible factor shows the share of the CPUs
  the simulator got, not its cost; the CPU column is the cost.
"""

from __future__ import annotations

import argparse
import json
import math
import os
import socket
import statistics
import subprocess
import sys
import tempfile
import time
from typing import Callable, Dict, List

import numpy as np

from _bytecode import byte_compile_minros  # benchmarks/ is the script's directory: on sys.path

HERE = os.path.dirname(os.path.abspath(__file__))
REPO = os.path.dirname(HERE)
VENV_PYTHON = os.path.join(REPO, ".venv", "bin", "python")
REFERENCE_PYTHON = "/usr/bin/python3"
ROBOTS = 5
RATE = 30
LASER_RATE = 10


# ------------------------------------------------------------------------------ the world

def cluttered_grid():
    from minros.sim.grid import GridMap

    rng = np.random.default_rng(3)
    data = np.where(rng.random((400, 400)) < 0.03, 100, 0).astype(np.int8)
    data[:3, :] = data[-3:, :] = data[:, :3] = data[:, -3:] = 100
    data[190:210, 5:80] = 0  # the robots' row (x 0.25 .. 4 m, y 9.5 .. 10.5 m) kept free
    return GridMap(data, 0.05, (0.0, 0.0, 0.0))


def make_world(name: str):
    from minros.sim import mapfile
    from minros.sim.world import DEFAULT_WORLD, Robot, World

    if name == "rooms":
        grid, _ = mapfile.load_map(DEFAULT_WORLD)
        starts = [(0.0, -1.0 + 0.5 * i) for i in range(ROBOTS)]
    else:
        grid = cluttered_grid()
        starts = [(0.5 + 0.6 * i, 10.0) for i in range(ROBOTS)]
    world = World(grid)
    for i, (x, y) in enumerate(starts):
        world.add_robot(Robot(f"tb3_{i}", x, y, 0.3 * i))
    return world


class UniformCaster:
    """Every beam sampled each half cell (numpy): the first wall sample is the range."""

    def __init__(self, grid, walls) -> None:
        self.grid, self.walls = grid, walls

    def cast(self, x, y, angles, max_range):
        grid = self.grid
        gx, gy = grid.to_cells(x, y)
        step = 0.5
        t = np.arange(0.0, max_range / grid.resolution + step, step)
        heading = grid.yaw_to_grid(angles)
        px = gx[:, None] + t[None, :] * np.cos(heading)[:, None]
        py = gy[:, None] + t[None, :] * np.sin(heading)[:, None]
        col, row = np.floor(px).astype(np.intp), np.floor(py).astype(np.intp)
        inside = (col >= 0) & (col < grid.width) & (row >= 0) & (row < grid.height)
        hit = np.zeros(px.shape, dtype=bool)
        hit[inside] = self.walls[row[inside], col[inside]]
        first = hit.argmax(axis=1)
        any_hit = hit[np.arange(len(first)), first]
        return np.where(any_hit, t[first] * grid.resolution, np.inf)


class PythonCaster:
    """A grid traversal (Amanatides and Woo) ray by ray, in plain Python."""

    def __init__(self, grid, walls) -> None:
        self.grid, self.walls = grid, walls.tolist()

    def cast(self, x, y, angles, max_range):
        grid, walls = self.grid, self.walls
        width, height = grid.width, grid.height
        gxs, gys = grid.to_cells(x, y)
        out = []
        limit = max_range / grid.resolution
        for gx, gy, a in zip(gxs.tolist(), gys.tolist(), grid.yaw_to_grid(angles).tolist()):
            dx, dy = math.cos(a), math.sin(a)
            col, row = math.floor(gx), math.floor(gy)
            step_c, step_r = (1 if dx > 0 else -1), (1 if dy > 0 else -1)
            t_c = ((col + (dx > 0)) - gx) / dx if dx else math.inf
            t_r = ((row + (dy > 0)) - gy) / dy if dy else math.inf
            dt_c, dt_r = (abs(1 / dx) if dx else math.inf), (abs(1 / dy) if dy else math.inf)
            t = 0.0
            result = math.inf
            while t <= limit and 0 <= col < width and 0 <= row < height:
                if walls[row][col]:
                    result = t * grid.resolution
                    break
                if t_c < t_r:
                    t, t_c, col = t_c, t_c + dt_c, col + step_c
                else:
                    t, t_r, row = t_r, t_r + dt_r, row + step_r
            out.append(result if result <= max_range else math.inf)
        return np.array(out)


def one_simulated_second(world, caster) -> Callable[[], None]:
    """A closure running 30 steps and 10 scans of every robot with ``caster``."""
    world.caster = caster
    for i, robot in enumerate(world.robots.values()):
        world.command(robot.name, 0.1, 0.3 * (-1) ** i)
    steps_per_scan = RATE // LASER_RATE

    def run() -> None:
        for step in range(RATE):
            for robot in world.robots.values():  # keep them moving (no watchdog here)
                robot.command_time = world.time
            world.step(1.0 / RATE)
            if step % steps_per_scan == 0:
                world.scan()

    return run


def time_scans(world, caster, seconds: float) -> float:
    """CPU milliseconds per 5-robot scan (best of repeated timings within ``seconds``).
    CPU time, not wall time: on a shared machine the wall clock also counts the time other
    processes hold the CPU."""
    world.caster = caster
    best, deadline = math.inf, time.perf_counter() + seconds
    while True:
        t0 = time.process_time()
        world.scan()
        best = min(best, time.process_time() - t0)
        if time.perf_counter() >= deadline:
            break
    return best * 1000.0


def time_second(run: Callable[[], None], seconds: float) -> float:
    """Simulated seconds per second of CPU (best single run within ``seconds``)."""
    best, deadline = math.inf, time.perf_counter() + seconds
    while True:
        t0 = time.process_time()
        run()
        best = min(best, time.process_time() - t0)
        if time.perf_counter() >= deadline:
            break
    return 1.0 / best


def world_part(rounds: int, seconds: float) -> List[List[str]]:
    from minros.sim.raycast import RayCaster

    rows = []
    for name in ("rooms", "cluttered"):
        results: Dict[str, Dict[str, List[float]]] = {}
        for _ in range(rounds):
            for label, cls in (("minros: distance-field marching (numpy)", RayCaster),
                               ("uniform half-cell sampling (numpy)", UniformCaster),
                               ("grid traversal per ray (pure Python)", PythonCaster)):
                world = make_world(name)
                caster = cls(world.grid, world.walls)
                budget = seconds if cls is not PythonCaster else max(1.0, seconds / 2)
                entry = results.setdefault(label, {"scan": [], "rtf": []})
                entry["scan"].append(time_scans(world, caster, budget / 2))
                entry["rtf"].append(time_second(one_simulated_second(world, caster), budget / 2))
        for label, entry in results.items():
            rows.append([name, label, f"{statistics.median(entry['scan']):.2f}",
                         f"{statistics.median(entry['rtf']):.1f}x"])
    return rows


# ------------------------------------------------------------------------------ the node

SUBSCRIBER = r'''
import json, sys, time
import rospy
from nav_msgs.msg import Odometry
from rosgraph_msgs.msg import Clock
from sensor_msgs.msg import LaserScan
from tf2_msgs.msg import TFMessage
robots, warmup, window = int(sys.argv[1]), float(sys.argv[2]), float(sys.argv[3])
rospy.init_node("sim_bench_sub", anonymous=True)
counts = {"scan": 0, "odom": 0, "tf": 0}
last = {"clock": None}
def count(kind):
    def cb(_m):
        counts[kind] += 1
    return cb
rospy.Subscriber("/clock", Clock, lambda m: last.__setitem__("clock", m.clock.to_sec()))
rospy.Subscriber("/tf", TFMessage, count("tf"))
for i in range(robots):
    rospy.Subscriber(f"/tb3_{i}/scan", LaserScan, count("scan"))
    rospy.Subscriber(f"/tb3_{i}/odom", Odometry, count("odom"))
deadline = time.monotonic() + 30
while last["clock"] is None and time.monotonic() < deadline:
    time.sleep(0.05)
time.sleep(warmup)
c0, w0, n0 = last["clock"], time.monotonic(), dict(counts)
time.sleep(window)
c1, w1 = last["clock"], time.monotonic()
sim = (c1 or 0) - (c0 or 0)
print(json.dumps({"rtf": sim / (w1 - w0), "sim": sim,
                  "scans_per_sim_s": (counts["scan"] - n0["scan"]) / sim if sim else 0.0,
                  "odom_per_sim_s": (counts["odom"] - n0["odom"]) / sim if sim else 0.0}), flush=True)
'''


def _free_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


def _env(port: int, home: str, reference: bool) -> dict:
    env = {k: v for k, v in os.environ.items() if not k.startswith("ROS_") and k != "PYTHONPATH"}
    env.update(ROS_MASTER_URI=f"http://localhost:{port}", ROS_HOSTNAME="localhost",
               ROS_HOME=home, ROS_LOG_DIR=os.path.join(home, "log"), PYTHONUNBUFFERED="1")
    if reference:
        env.pop("VIRTUAL_ENV", None)
        env["PATH"] = "/usr/bin:/bin"
        env["PYTHONPATH"] = os.path.join(REPO, "src")  # minros.sim, not minros's rospy
    return env


def _cpu_seconds(pid: int) -> float:
    with open(f"/proc/{pid}/stat") as f:
        fields = f.read().rsplit(")", 1)[1].split()
    return (int(fields[11]) + int(fields[12])) / os.sysconf("SC_CLK_TCK")


def node_run(contender: str, speed: float, seconds: float, port: int, home: str) -> dict:
    reference = contender == "rospy"
    python = REFERENCE_PYTHON if reference else VENV_PYTHON
    argv = [python, "-m", "minros.nodes.minros_sim.sim_node", "--robots", str(ROBOTS),
            "--laser-rate", str(LASER_RATE), "--rate", str(RATE), "--clock",
            "--speed", str(speed), "--watchdog", "0"]
    sim = subprocess.Popen(argv, env=_env(port, home, reference), stdout=subprocess.DEVNULL,
                           stderr=subprocess.DEVNULL)
    try:
        sub = subprocess.Popen([VENV_PYTHON, "-c", SUBSCRIBER, str(ROBOTS), "2", str(seconds)],
                               env=_env(port, home, False), stdout=subprocess.PIPE,
                               stderr=subprocess.DEVNULL, text=True)
        # the simulator's CPU over the subscriber's window (after its warm-up)
        time.sleep(2.5)
        cpu0, wall0 = _cpu_seconds(sim.pid), time.monotonic()
        out, _ = sub.communicate(timeout=seconds + 60)
        cpu1, wall1 = _cpu_seconds(sim.pid), time.monotonic()
        result = json.loads(out.strip().splitlines()[-1])
        result["cpu"] = 100.0 * (cpu1 - cpu0) / (wall1 - wall0)
        # simulated seconds per second of the simulator's CPU: what a free core would give
        result["per_cpu"] = result["rtf"] * 100.0 / max(result["cpu"], 1e-9)
        return result
    finally:
        sim.terminate()
        try:
            sim.wait(10)
        except subprocess.TimeoutExpired:
            sim.kill()


def node_part(rounds: int, seconds: float) -> List[List[str]]:
    home = tempfile.mkdtemp(prefix="minros-bench-sim-")
    os.makedirs(os.path.join(home, "log"), exist_ok=True)
    port = _free_port()
    master = subprocess.Popen([VENV_PYTHON, "-m", "minros.master", "-p", str(port)],
                              env=_env(port, home, False), stdout=subprocess.DEVNULL,
                              stderr=subprocess.DEVNULL)
    contenders = ["minros"] + (["rospy"] if _reference_available() else [])
    results: Dict[tuple, List[dict]] = {}
    try:
        time.sleep(1.5)
        for _ in range(rounds):
            for contender in contenders:
                for speed in (0.0, 1.0):
                    results.setdefault((contender, speed), []).append(
                        node_run(contender, speed, seconds, port, home))
    finally:
        master.terminate()
        master.wait(10)
    rows = []
    for (contender, speed), runs in results.items():
        def med(key: str, runs: List[dict] = runs) -> float:
            return statistics.median(r[key] for r in runs)
        label = "sim_node on minros" if contender == "minros" else "sim_node on Debian's rospy"
        rows.append([label, "as fast as possible" if speed == 0 else "real time",
                     f"{med('rtf'):.1f}x", f"{med('per_cpu'):.1f}x",
                     f"{med('scans_per_sim_s'):.0f}", f"{med('cpu'):.0f} %"])
    return rows


def _reference_available() -> bool:
    if not os.path.exists(REFERENCE_PYTHON):
        return False
    probe = subprocess.run([REFERENCE_PYTHON, "-c", "import rospy, tf2_ros, numpy, cv2, yaml"],
                           env=_env(0, tempfile.gettempdir(), True), capture_output=True)
    return probe.returncode == 0


def table(header: List[str], rows: List[List[str]]) -> str:
    widths = [max(len(str(r[i])) for r in [header] + rows) for i in range(len(header))]
    lines = [" | ".join(str(c).ljust(w) for c, w in zip(header, widths))]
    lines.append("-+-".join("-" * w for w in widths))
    lines += [" | ".join(str(c).ljust(w) for c, w in zip(r, widths)) for r in rows]
    return "\n".join(lines)


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0],
                                     formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--rounds", type=int, default=3)
    parser.add_argument("--seconds", type=float, default=8.0,
                        help="measuring window of each run (default 8)")
    parser.add_argument("--part", choices=("world", "node", "both"), default="both")
    args = parser.parse_args()
    byte_compile_minros()
    print(f"5 robots x 360 beams, laser {LASER_RATE} Hz, {RATE} steps per simulated second; "
          f"median of {args.rounds} rounds; {os.cpu_count()} CPUs, load average "
          f"{open('/proc/loadavg').read().split()[0]}")
    if args.part in ("world", "both"):
        rows = world_part(args.rounds, args.seconds / 4)
        print()
        print(table(["world", "ray caster", "CPU ms per 5-robot scan", "real-time factor (CPU)"],
                    rows))
    if args.part in ("node", "both"):
        rows = node_part(args.rounds, args.seconds)
        print()
        print(table(["simulator", "pace", "real-time factor", "sim s per CPU s",
                     "scans per sim s", "simulator CPU"], rows))
    return 0


if __name__ == "__main__":
    sys.exit(main())
