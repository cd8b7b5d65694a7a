"""minros turtlesim driven by Debian's real ROS 1 tools (rostopic, rosservice, rosparam, rosnode).

Debian does not package turtlesim, so its tools cannot import turtlesim/Pose or turtlesim/Spawn;
the fixture generates those Python classes with Debian's own genpy from the bundled .msg/.srv
files (as catkin would) and puts them on the reference tools' PYTHONPATH.
"""

from __future__ import annotations

import re
import subprocess
from pathlib import Path

import pytest

from minros.packages import find_package
from support import PYTHON, Proc, reference_env, require_reference, ros_env

pytestmark = pytest.mark.interop

PROBE = str(Path(__file__).resolve().parent / "turtlesim_probe.py")


@pytest.fixture(scope="module")
def turtlesim_pythonpath(tmp_path_factory) -> str:
    """Debian-genpy-generated ``turtlesim.msg``/``turtlesim.srv`` for the reference tools."""
    require_reference()
    share = Path(find_package("turtlesim"))
    out = tmp_path_factory.mktemp("turtlesim_gen")
    env = reference_env({})
    pkg = out / "turtlesim"
    for kind, tool in (("msg", "genmsg_py.py"), ("srv", "gensrv_py.py")):
        files = sorted(str(p) for p in (share / kind).glob(f"*.{kind}"))
        subprocess.run([
            "/usr/bin/python3", f"/usr/lib/genpy/{tool}", "-p", "turtlesim",
            "-o", str(pkg / kind), "-I", f"turtlesim:{share / 'msg'}",
            "-I", "std_msgs:/usr/share/std_msgs/msg", *files],
            env=env, check=True, capture_output=True, timeout=60)
        subprocess.run(["/usr/bin/python3", f"/usr/lib/genpy/{tool}", "--initpy", "-p",
                        "turtlesim", "-o", str(pkg / kind)],
                       env=env, check=True, capture_output=True, timeout=60)
    (pkg / "__init__.py").write_text("")
    return str(out)


def ref_env(port: int, home: Path, pythonpath: str) -> dict:
    env = reference_env(ros_env(port, home))
    env["PYTHONPATH"] = pythonpath  # only the generated turtlesim package, nothing of minros
    return env


def ref(argv, env, timeout: float = 20) -> subprocess.CompletedProcess:
    return subprocess.run(argv, env=env, capture_output=True, text=True, timeout=timeout)


@pytest.fixture
def sim_under_core(minros_core, ros_home):
    proc = Proc([PYTHON, "-m", "minros", "run", "turtlesim", "turtlesim_node"],
                ros_env(minros_core, ros_home, {"MINROS_HEADLESS": "1"}))
    proc.read_until("Spawning turtle [turtle1]", timeout=15)
    try:
        yield minros_core
    finally:
        proc.stop()


def test_debian_rostopic_drives_and_reads_the_turtle(sim_under_core, ros_home, turtlesim_pythonpath):
    port = sim_under_core
    env = ref_env(port, ros_home, turtlesim_pythonpath)
    echo = ref(["/usr/bin/rostopic", "echo", "-n", "1", "/turtle1/pose"], env)
    assert echo.returncode == 0, echo.stderr
    assert "x: 5.544444561004639" in echo.stdout and "linear_velocity: 0.0" in echo.stdout
    pub = Proc(["/usr/bin/rostopic", "pub", "-r", "20", "/turtle1/cmd_vel", "geometry_msgs/Twist",
                "--", "[2.0, 0.0, 0.0]", "[0.0, 0.0, 1.8]"], env)
    try:
        moving = Proc([PYTHON, PROBE, "wait_moving", "/turtle1/pose", "2.0"], ros_env(port, ros_home))
        out = moving.read_until("RESULT ", timeout=20)
        moving.stop()
        assert '"angular_velocity": 1.7999999523162842' in out  # float32(1.8) from Debian's Twist
        hz = Proc(["/usr/bin/rostopic", "hz", "-w", "30", "/turtle1/pose"], env)
        try:
            line = hz.read_until("average rate", timeout=15)
        finally:
            hz.stop()
        rate = float(re.search(r"average rate: ([0-9.]+)", line).group(1))
        assert 40.0 < rate < 75.0, rate
    finally:
        pub.stop()
    color = ref(["/usr/bin/rostopic", "echo", "-n", "1", "/turtle1/color_sensor"], env)
    assert color.returncode == 0 and "r: 179" in color.stdout  # the pen trail under the turtle


def test_debian_rosservice_spawn_kill_and_errors(sim_under_core, ros_home, turtlesim_pythonpath):
    env = ref_env(sim_under_core, ros_home, turtlesim_pythonpath)
    spawned = ref(["/usr/bin/rosservice", "call", "/spawn", "2", "2", "0.5", ""], env)
    assert spawned.returncode == 0, spawned.stderr
    assert spawned.stdout.strip() == 'name: "turtle2"'
    dup = ref(["/usr/bin/rosservice", "call", "/spawn", "2", "2", "0.5", "turtle2"], env)
    assert dup.returncode != 0
    assert "ERROR: service [/spawn] responded with an error: b''" in dup.stderr  # as roscpp's false
    topics = ref(["/usr/bin/rostopic", "list"], env).stdout.split()
    assert {"/turtle2/pose", "/turtle2/cmd_vel", "/turtle2/color_sensor"} <= set(topics)
    info = ref(["/usr/bin/rosservice", "info", "/turtle2/set_pen"], env)
    assert "Type: turtlesim/SetPen" in info.stdout and "Args: r g b width off" in info.stdout
    assert ref(["/usr/bin/rosservice", "call", "/turtle2/set_pen", "255", "0", "0", "0", "0"],
               env).returncode == 0
    assert ref(["/usr/bin/rosservice", "call", "/kill", "turtle2"], env).returncode == 0
    missing = ref(["/usr/bin/rosservice", "call", "/kill", "turtle2"], env)
    assert missing.returncode != 0 and "responded with an error" in missing.stderr
    topics = ref(["/usr/bin/rostopic", "list"], env).stdout.split()
    assert "/turtle2/pose" not in topics and "/turtle1/pose" in topics


def test_minros_turtlesim_under_debian_rosmaster(debian_rosmaster, ros_home, turtlesim_pythonpath):
    port = debian_rosmaster
    proc = Proc([PYTHON, "-m", "minros.nodes.turtlesim.turtlesim_node", "--headless"],
                ros_env(port, ros_home))
    try:
        proc.read_until("Spawning turtle [turtle1]", timeout=15)
        env = ref_env(port, ros_home, turtlesim_pythonpath)
        params = ref(["/usr/bin/rosparam", "get", "/turtlesim"], env)
        assert params.returncode == 0, params.stderr
        assert {"background_r: 69", "background_g: 86", "background_b: 255"} <= set(
            params.stdout.split("\n"))
        nodes = ref(["/usr/bin/rosnode", "info", "/turtlesim"], env)
        assert "/turtle1/pose [turtlesim/Pose]" in nodes.stdout
        subscriptions = nodes.stdout.split("Subscriptions:", 1)[1].split("Services:", 1)[0]
        assert " * /turtle1/cmd_vel [" in subscriptions  # type unknown to the master: sub only
        assert "/spawn" in nodes.stdout and "/turtle1/teleport_absolute" in nodes.stdout
        reset = ref(["/usr/bin/rosservice", "call", "/reset"], env)
        assert reset.returncode == 0, reset.stderr
    finally:
        out = proc.stop()
    assert "Resetting turtlesim." in out
