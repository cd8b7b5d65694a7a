"""turtlesim as processes: ``rosrun turtlesim turtlesim_node`` under ``minros core``, driven and
observed by minros client nodes (tests/integration/turtlesim_probe.py), teleop through a pty,
mimic across two simulators, draw_square, and the PNG snapshot."""

from __future__ import annotations

import json
import math
import os
import pty
import shutil
import subprocess
import termios
import time
from pathlib import Path

import cv2
import numpy as np
import pytest

from support import IN_CI, PYTHON, Proc, free_port, ros_env, wait_for_master, wait_until

PROBE = str(Path(__file__).resolve().parent / "turtlesim_probe.py")
CENTER = "5.544445"


def headless_env(port: int, home: Path) -> dict:
    return ros_env(port, home, {"MINROS_HEADLESS": "1"})


def start_turtlesim(port: int, home: Path, *args: str) -> Proc:
    proc = Proc([PYTHON, "-m", "minros", "run", "turtlesim", "turtlesim_node", *args],
                headless_env(port, home))
    proc.startup = proc.read_until("Spawning turtle [turtle1]", timeout=15)
    return proc


def probe(port: int, home: Path, *args: str, timeout: float = 20) -> dict:
    proc = Proc([PYTHON, PROBE, *args], ros_env(port, home))
    try:
        out = proc.read_until("RESULT ", timeout=timeout)
    finally:
        rest = proc.stop()
    for line in (out + rest).splitlines():
        if line.startswith("RESULT "):
            return json.loads(line[len("RESULT "):])
    raise AssertionError(out + rest)


@pytest.fixture
def turtlesim(minros_core, ros_home, tmp_path):
    snapshot = tmp_path / "frame.png"
    proc = start_turtlesim(minros_core, ros_home, "--snapshot", str(snapshot))
    try:
        yield proc, minros_core, ros_home, snapshot
    finally:
        proc.stop()


@pytest.mark.smoke
def test_startup_lines_and_headless_notice(minros_core, ros_home, tmp_path):
    snapshot = tmp_path / "shot.png"
    # Private parameters from the command line: a background colour and the ~snapshot file.
    proc = Proc([PYTHON, "-m", "minros", "run", "turtlesim", "turtlesim_node",
                 "_background_r:=0", f"_snapshot:={snapshot}"], headless_env(minros_core, ros_home))
    try:
        out = proc.read_until("without a window", timeout=15)
    finally:
        out += proc.stop()
    assert "Starting turtlesim with node name /turtlesim" in out
    assert f"Spawning turtle [turtle1] at x=[{CENTER}], y=[{CENTER}], theta=[0.000000]" in out
    assert out.count("without a window") == 1
    assert "Traceback" not in out
    frame = cv2.imread(str(snapshot))  # written at shutdown
    assert frame is not None and tuple(frame[0, 0]) == (255, 86, 0)  # BGR of (0, 86, 255)


def test_cmd_vel_moves_the_pose_and_pose_rate(turtlesim):
    proc, port, home, snapshot = turtlesim
    result = probe(port, home, "drive", "/turtle1")
    first, moving = result["first"], result["moving"]
    assert first["x"] == pytest.approx(float(CENTER), abs=1e-6)
    assert (first["linear_velocity"], first["angular_velocity"]) == (0.0, 0.0)
    assert moving["linear_velocity"] == 2.0 and moving["angular_velocity"] == 1.0
    assert moving["x"] != first["x"] and moving["theta"] > 0
    rate = probe(port, home, "rate", "/turtle1/pose", "1.5")["rate"]
    assert 40.0 < rate < 75.0, rate  # 16 ms timer: 62.5 Hz even when idle (slack for loaded CI)


def test_services_spawn_kill_pen_teleport_clear(turtlesim):
    proc, port, home, snapshot = turtlesim
    out = probe(port, home, "services", timeout=30)
    assert out["spawned"] == "turtle2" and out["named"] == "leo"
    assert out["leo_pose"]["x"] == 1.0 and out["leo_pose"]["y"] == 1.0
    assert out["duplicate_error"].startswith("service [/spawn] responded with an error")
    assert out["illegal_error"].startswith("service [/spawn] responded with an error")
    assert "Cannot spawn turtle [no way]: not a legal ROS name" in out["illegal_error"]
    assert {"/leo/pose", "/leo/color_sensor"} <= set(out["topics_before_kill"])
    assert not any(t.startswith("/leo/") for t in out["topics_after_kill"])
    assert "/turtle2/pose" in out["topics_after_kill"]
    assert out["kill_unknown_error"].startswith("service [/kill] responded with an error")
    assert out["color"] == [255, 0, 0]
    assert out["after_clear"] == [10, 86, 255]
    assert out["params"] == {"background_r": 10, "background_g": 86, "background_b": 255}
    assert "non-finite value (x=nan)" in out["nan_teleport_error"]
    assert all(math.isfinite(v) for v in out["pose_after_inf"].values())
    log = proc.stop()
    assert "A turtled named [leo] already exists" in log
    assert "Tried to kill turtle [leo], which does not exist" in log
    assert "Traceback" not in log and "error processing request" not in log
    # The snapshot written at shutdown: cleared to the new background, turtle1 drawn at (2, 2).
    frame = cv2.imread(str(snapshot))
    assert frame is not None and frame.shape == (500, 500, 3)
    assert tuple(frame[5, 495]) == (255, 86, 10)  # BGR of background (10, 86, 255)
    row, col = round(500 - 1 - 2.0 * 45), round(2.0 * 45)
    patch = frame[row - 8:row + 8, col - 8:col + 8]
    assert not np.all(patch == (255, 86, 10))


def test_teleop_key_through_a_pty(turtlesim):
    proc, port, home, snapshot = turtlesim
    watcher = Proc([PYTHON, PROBE, "first_twist", "/turtle1/cmd_vel"], ros_env(port, home))
    master_fd, slave_fd = pty.openpty()
    teleop = Proc([PYTHON, "-m", "minros", "run", "turtlesim", "turtle_teleop_key"],
                  ros_env(port, home), stdin=slave_fd)
    try:
        watcher.read_until("READY", timeout=15)
        # The banner goes to stdout (a pipe here); the pty is stdin, which must be in raw mode.
        # (Only the first line is awaited: read_until cannot see lines already buffered.)
        teleop.read_until("Reading from keyboard", timeout=15)
        attrs = termios.tcgetattr(slave_fd)
        assert not attrs[3] & termios.ICANON and not attrs[3] & termios.ECHO
        assert attrs[3] & termios.ISIG  # Ctrl-C still interrupts
        deadline = time.monotonic() + 15
        result = None
        while result is None and time.monotonic() < deadline:
            os.write(master_fd, b"\x1b[A")  # arrow up: one Twist per key press
            try:
                result = watcher.read_until("RESULT ", timeout=0.3)
            except AssertionError:
                continue
        assert result is not None, "no Twist seen on /turtle1/cmd_vel"
        twist = json.loads(result.split("RESULT ", 1)[1].splitlines()[0])
        assert twist == {"linear_x": 2.0, "angular_z": 0.0, "linear_y": 0.0}
        os.write(master_fd, b"q")
        teleop.popen.wait(10)
        assert teleop.popen.returncode == 0
        assert termios.tcgetattr(slave_fd)[3] & termios.ICANON  # terminal restored
    finally:
        watcher.stop()
        teleop.stop()
        os.close(master_fd)
        os.close(slave_fd)


def test_teleop_without_a_terminal_says_so_once(minros_core, ros_home):
    proc = subprocess.run([PYTHON, "-m", "minros", "run", "turtlesim", "turtle_teleop_key"],
                          input=b"xyq", env=ros_env(minros_core, ros_home), capture_output=True,
                          timeout=20)
    assert proc.returncode == 0
    err = proc.stderr.decode()
    assert err.count("stdin is not a terminal") == 1 and "Traceback" not in err
    assert proc.stdout.decode().splitlines()[:3] == [
        "Reading from keyboard", "---------------------------",
        "Use arrow keys to move the turtle. 'q' to quit."]


def test_mimic_follows_across_two_simulators(minros_core, ros_home):
    port = minros_core
    sims = [start_turtlesim(port, ros_home, "__name:=sim", f"__ns:=turtlesim{i}") for i in (1, 2)]
    mimic = Proc([PYTHON, "-m", "minros", "run", "turtlesim", "mimic",
                  "input:=turtlesim1/turtle1", "output:=turtlesim2/turtle1"], ros_env(port, ros_home))
    try:
        assert "Starting turtlesim with node name /turtlesim1/sim" in sims[0].startup
        # Watch turtlesim2 first, then keep turtlesim1 driven until the follower moved (the
        # mimic node may still be connecting when the driving starts).
        watcher = Proc([PYTHON, PROBE, "wait_moving", "/turtlesim2/turtle1/pose", "2.0"],
                       ros_env(port, ros_home))
        driver = None
        try:
            watcher.read_until("READY", timeout=15)
            driver = Proc([PYTHON, PROBE, "drive", "/turtlesim1/turtle1", "30"],
                          ros_env(port, ros_home))
            out = watcher.read_until("RESULT ", timeout=20)
        finally:
            watcher.stop()
            if driver is not None:
                driver.stop()
        follower = json.loads(out.split("RESULT ", 1)[1].splitlines()[0])["pose"]
        assert follower["angular_velocity"] == 1.0
        assert follower["x"] != pytest.approx(float(CENTER), abs=1e-3)
    finally:
        mimic.stop()
        for s in sims:
            s.stop()


def test_draw_square_resets_and_reaches_its_first_goal(turtlesim):
    proc, port, home, snapshot = turtlesim
    square = Proc([PYTHON, "-m", "minros", "run", "turtlesim", "draw_square"], ros_env(port, home))
    try:
        # One read: lines printed together may sit in one buffered chunk.
        out = square.read_until(", 1.570796]", timeout=20)  # the turn goal, set in place
    finally:
        out += square.stop()
    assert "New goal [7.544445 5.544445, 0.000000]" in out  # 2 m ahead of the reset turtle1
    assert out.index("Reached goal") > out.index("New goal [7.544445")
    assert "Traceback" not in out
    log = proc.stop()
    assert "Resetting turtlesim." in log


def _read_xwd(path: Path) -> np.ndarray:
    """The 24/32-bit ZPixmap screen dump Xvfb keeps in its -fbdir, as an (h, w, 3) BGR array."""
    import struct

    data = path.read_bytes()
    fields = struct.unpack(">25I", data[:100])
    header_size, width, height, bytes_per_line, ncolors = (
        fields[0], fields[4], fields[5], fields[12], fields[19])
    start = header_size + ncolors * 12
    rows = np.frombuffer(data[start:start + bytes_per_line * height], np.uint8)
    return rows.reshape(height, bytes_per_line)[:, :width * 4].reshape(height, width, 4)[:, :, :3]


@pytest.mark.timing
def test_window_on_a_virtual_display(minros_core, ros_home, tmp_path):
    if not shutil.which("Xvfb"):
        if IN_CI:  # scripts/install-ros-reference.sh installs it for exactly this test
            pytest.fail("Xvfb is not installed")
        pytest.skip("Xvfb not installed (the window is optional)")
    read_fd, write_fd = os.pipe()
    xvfb = subprocess.Popen(["Xvfb", "-displayfd", str(write_fd), "-screen", "0", "640x560x24",
                             "-fbdir", str(tmp_path), "-nolisten", "tcp"],
                            pass_fds=[write_fd], stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    os.close(write_fd)
    try:
        with os.fdopen(read_fd) as numbers:
            display = numbers.readline().strip()
        assert display.isdigit(), "Xvfb did not report its display"
        env = ros_env(minros_core, ros_home, {"DISPLAY": f":{display}"})
        sim = Proc([PYTHON, "-m", "minros.nodes.turtlesim.turtlesim_node"], env)
        try:
            sim.read_until("Spawning turtle [turtle1]", timeout=15)

            def background_shown():
                screen = _read_xwd(tmp_path / "Xvfb_screen0")
                return np.all(screen == (255, 86, 69), axis=2).sum() > 200_000  # BGR

            wait_until(background_shown, timeout=10, what="turtlesim window on the screen")
            screen = _read_xwd(tmp_path / "Xvfb_screen0")
            ys, xs = np.all(screen == (255, 86, 69), axis=2).nonzero()
            top, left = ys.min(), xs.min()  # the canvas inside the window
            assert (ys.max() - top, xs.max() - left) == (499, 499)
            icon = screen[top + 230:top + 270, left + 230:left + 270]
            assert np.any(icon != (255, 86, 69), axis=2).sum() > 300  # turtle1 at the centre
            assert not np.any(np.all(screen == (255, 184, 179), axis=2))  # no pen trail yet
            probe(minros_core, ros_home, "drive", "/turtle1")

            def trail_shown():
                screen = _read_xwd(tmp_path / "Xvfb_screen0")
                return np.all(screen == (255, 184, 179), axis=2).sum() > 30  # BGR pen colour

            wait_until(trail_shown, timeout=10, what="the pen trail in the window")
        finally:
            out = sim.stop()
        assert "without a window" not in out and "Traceback" not in out
    finally:
        xvfb.terminate()
        xvfb.wait(5)


def test_seed_workflow_roscore_rosrun_and_arrow_keys(ros_home, tmp_path):
    """The seed's three terminals: roscore, rosrun turtlesim turtlesim_node, rosrun turtlesim
    turtle_teleop_key, then a left-arrow key press turns the turtle (angular 2.0 in the pose)."""
    bin_dir = Path(PYTHON).parent
    port = free_port()
    env = ros_env(port, ros_home, {"MINROS_HEADLESS": "1"})
    core = Proc([str(bin_dir / "roscore"), "-p", str(port)], env)
    procs = [core]
    master_fd, slave_fd = pty.openpty()
    try:
        wait_for_master(port)
        sim = Proc([str(bin_dir / "rosrun"), "turtlesim", "turtlesim_node"], env)
        procs.append(sim)
        sim.read_until("Spawning turtle [turtle1]", timeout=15)
        teleop = Proc([str(bin_dir / "rosrun"), "turtlesim", "turtle_teleop_key"], env,
                      stdin=slave_fd)
        procs.append(teleop)
        teleop.read_until("Reading from keyboard", timeout=15)
        watcher = Proc([PYTHON, PROBE, "wait_pose", "/turtle1/pose", "angular_velocity", "2.0"],
                       ros_env(port, ros_home))
        procs.append(watcher)
        deadline = time.monotonic() + 15
        result = None
        while result is None and time.monotonic() < deadline:
            os.write(master_fd, b"\x1b[D")  # left arrow
            try:
                result = watcher.read_until("RESULT ", timeout=0.3)
            except AssertionError:
                continue
        assert result is not None, "the turtle never turned"
        pose = json.loads(result.split("RESULT ", 1)[1].splitlines()[0])["pose"]
        assert pose["linear_velocity"] == 0.0 and pose["angular_velocity"] == 2.0
        assert pose["x"] == pytest.approx(float(CENTER), abs=1e-6)  # turning in place
    finally:
        for proc in reversed(procs):
            proc.stop()
        os.close(master_fd)
        os.close(slave_fd)


def test_teleop_ctrl_c_restores_the_terminal(minros_core, ros_home):
    import signal

    master_fd, slave_fd = pty.openpty()
    teleop = Proc([PYTHON, "-m", "minros.nodes.turtlesim.turtle_teleop_key"],
                  ros_env(minros_core, ros_home), stdin=slave_fd)
    try:
        teleop.read_until("Reading from keyboard", timeout=15)
        assert not termios.tcgetattr(slave_fd)[3] & termios.ICANON
        os.kill(teleop.pid, signal.SIGINT)  # what Ctrl-C sends (ISIG stays on in the raw mode)
        teleop.popen.wait(10)
        assert termios.tcgetattr(slave_fd)[3] & termios.ICANON
        assert termios.tcgetattr(slave_fd)[3] & termios.ECHO
        assert "Traceback" not in teleop.output()
    finally:
        teleop.stop()
        os.close(master_fd)
        os.close(slave_fd)


def test_ctrl_c_while_waiting_for_the_master_is_one_line(ros_home):
    import signal

    port = free_port()  # nothing listens there
    sim = Proc([PYTHON, "-m", "minros", "run", "turtlesim", "turtlesim_node"],
               headless_env(port, ros_home))
    try:
        sim.read_until("master may not be running yet", timeout=15)
        os.killpg(sim.pid, signal.SIGINT)
        sim.popen.wait(10)
    finally:
        out = sim.stop()
    assert "Traceback" not in out
    assert "turtlesim_node: init_node interrupted before it could complete" in out
