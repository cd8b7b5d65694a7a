"""The actionlib and dynamic_reconfigure tutorials, unmodified, from a catkin workspace.

A user's steps in bash: ``catkin_create_pkg`` the two tutorial packages, add the tutorial files
(``library_tutorials/``: actionlib_tutorials' Fibonacci.action, fibonacci_server.py and
fibonacci_client.py as common_tutorials (noetic-devel) ships them; dynamic_tutorials'
Tutorials.cfg, server.py and client.py as the dynamic_reconfigure wiki tutorials give them),
``catkin_make``, source ``devel/setup.bash``, then ``rosrun`` the nodes on ``roscore``. The
Fibonacci client (order 20 at 1 Hz) runs while the dynamic_reconfigure server is reconfigured
by ``dynparam`` and by the tutorial client.
"""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import pytest

from support import Proc, free_port, wait_for_master

TUTORIALS = Path(__file__).resolve().parent / "library_tutorials"
VENV_BIN = str(Path(sys.executable).parent)

BUILD = f"""
mkdir -p ~/catkin_ws/src
cd ~/catkin_ws/src
catkin_create_pkg actionlib_tutorials actionlib message_generation roscpp rospy std_msgs actionlib_msgs
cp -r {TUTORIALS}/actionlib_tutorials/action {TUTORIALS}/actionlib_tutorials/scripts actionlib_tutorials/
catkin_create_pkg dynamic_tutorials rospy roscpp dynamic_reconfigure
cp -r {TUTORIALS}/dynamic_tutorials/cfg {TUTORIALS}/dynamic_tutorials/nodes dynamic_tutorials/
cd ~/catkin_ws
catkin_make
"""

FIBONACCI = ("Result: 0, 1, 1, 2, 3, 5, 8, 13, 21, 34, 55, 89, 144, 233, 377, 610, 987, 1597, "
             "2584, 4181, 6765")


@pytest.fixture
def desk(tmp_path: Path):
    home = tmp_path / "home"
    home.mkdir()
    port = free_port()
    env = {"HOME": str(home), "PATH": f"{VENV_BIN}:/usr/bin:/bin", "LANG": "C.UTF-8",
           "ROS_MASTER_URI": f"http://localhost:{port}", "ROS_HOSTNAME": "localhost",
           "PYTHONUNBUFFERED": "1"}
    terminals: list = []

    def run(commands: str, timeout: float = 60) -> str:
        done = subprocess.run(["bash", "-e", "-c", commands], cwd=home, env=env,
                              capture_output=True, text=True, timeout=timeout)
        assert done.returncode == 0, f"{commands}\n{done.stdout}\n{done.stderr}"
        return done.stdout + done.stderr

    def open_terminal(commands: str) -> Proc:
        proc = Proc(["bash", "-c", commands], env, cwd=home)
        terminals.append(proc)
        return proc

    yield run, open_terminal, port
    for proc in reversed(terminals):
        proc.stop()


def test_fibonacci_and_dynamic_reconfigure_tutorials(desk) -> None:
    run, open_terminal, port = desk
    built = run(BUILD)
    assert "-- actionlib_tutorials: 7 messages, 0 services" in built
    assert "Generating reconfiguration files for Tutorials in dynamic_tutorials" in built
    open_terminal(f"roscore -p {port}\n")
    wait_for_master(port, timeout=20)
    source = "source ~/catkin_ws/devel/setup.bash\n"
    fib_server = open_terminal(source + "rosrun actionlib_tutorials fibonacci_server.py\n")
    dyn_server = open_terminal(source + "rosrun dynamic_tutorials server.py\n")
    dyn_server.read_until("Reconfigure Request: 50, 0.5,", 30)
    fib_client = open_terminal(source + "rosrun actionlib_tutorials fibonacci_client.py\n")
    fib_server.read_until("/fibonacci: Executing, creating fibonacci sequence of order 20 with "
                          "seeds 0, 1", 30)

    # meanwhile, tune the dynamic_reconfigure tutorial server
    run(source + "rosrun dynamic_reconfigure dynparam set /dynamic_tutorials "
                 "\"{'int_param': 7, 'size': 'ExtraLarge', 'str_param': 'tuned'}\"")
    dyn_server.read_until("Reconfigure Request: 7, 0.5,", 10)
    got = run(source + "rosrun dynamic_reconfigure dynparam get /dynamic_tutorials")
    assert got.startswith("{'bool_param': True, 'int_param': 7, 'size': 3, 'str_param': 'tuned', "
                          "'double_param': 0.5, 'groups': {")
    refused = run(source + "rosrun dynamic_reconfigure dynparam set /dynamic_tutorials "
                           "double_param lots")
    assert refused == ("error updating parameters: can't set parameter 'double_param' of "
                       "<class 'float'>: could not convert string to float: 'lots'\n")
    assert run(source + "rosparam get /dynamic_tutorials/str_param") == "tuned\n"
    dyn_client = open_terminal(source + "rosrun dynamic_tutorials client.py\n")
    dyn_client.read_until("Config set to 1, 0.5, ", 30)  # its first update: x=1, 1/(x+1)
    dyn_server.read_until("Reconfigure Request: 1, 0.5,", 10)

    out = fib_client.read_until("Result:", 60)
    assert FIBONACCI in out
    assert fib_server.read_until("/fibonacci: Succeeded", 10)
