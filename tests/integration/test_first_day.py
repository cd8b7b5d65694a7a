"""A newcomer's first day, as the README leads it: the talker stops quietly on Ctrl-C,
``minros --version``, ``rosbag --help`` offers only what exists, ``minros ws --help`` explains,
and a ROS_MASTER_URI without its scheme is named, with the fix, by whatever reads it."""

from __future__ import annotations

import importlib.metadata
import re
import signal
import subprocess
import time
from pathlib import Path
from typing import Dict, List

import pytest

import minros
from support import PYTHON, REPO, Proc, ros_env

VENV_BIN = Path(PYTHON).parent


def readme_talker() -> str:
    """The Python script the README's talker section shows."""
    readme = (REPO / "README.md").read_text()
    section = readme.split("Your own scripts are plain rospy", 1)[1]
    return section.split("```python\n", 1)[1].split("```", 1)[0]


#: the README's talker before the tutorial's try/except was put back (the loop bare), with a
#: line to say it runs
BARE_LOOP = """\
import rospy
from std_msgs.msg import String

rospy.init_node('talker', anonymous=True)
pub = rospy.Publisher('chatter', String, queue_size=10)
rate = rospy.Rate(10)
print("hello world: publishing", flush=True)
while not rospy.is_shutdown():
    pub.publish("hello world %s" % rospy.get_time())
    rate.sleep()
"""

#: a loop that never looks at is_shutdown(): rospy's spins on forever after Ctrl-C
ENDLESS_LOOP = """\
import rospy

rospy.init_node('talker', anonymous=True)
rate = rospy.Rate(10)
while True:
    rospy.loginfo("hello world")
    rate.sleep()
"""


def ctrl_c(script: Path, env: Dict[str, str], python: str = PYTHON) -> tuple:
    """Run ``script`` until it logs "hello world", then SIGINT its process only (a terminal's
    Ctrl-C); returns (exit status, output), bounded."""
    proc = Proc([python, str(script)], env)
    try:
        proc.read_until("hello world", 30)
        proc.popen.send_signal(signal.SIGINT)
        try:
            status = proc.popen.wait(15)
        except subprocess.TimeoutExpired:
            status = None
    finally:
        out = proc.stop()
    return status, out


def test_the_readme_talker_stops_quietly_on_ctrl_c(minros_core, ros_home, tmp_path):
    script = tmp_path / "talker.py"
    script.write_text(readme_talker())
    assert "except rospy.ROSInterruptException:" in script.read_text()  # the tutorial's form
    status, out = ctrl_c(script, ros_env(minros_core, ros_home))
    assert status == 0 and "Traceback" not in out, out


def test_a_bare_rate_loop_stops_quietly_on_ctrl_c_as_under_rospy(minros_core, ros_home, tmp_path):
    """rospy's Rate.sleep on the wall clock raises nothing at shutdown: the while condition
    ends the loop (Debian's rospy exits 0, silent; checked in the interop tests)."""
    script = tmp_path / "talker.py"
    script.write_text(BARE_LOOP)
    status, out = ctrl_c(script, ros_env(minros_core, ros_home))
    assert status == 0 and "Traceback" not in out, out


def test_a_loop_that_never_checks_shutdown_ends_with_rospys_names(minros_core, ros_home, tmp_path):
    """The next sleep after shutdown raises, so the loop ends (rospy's spins forever), and the
    traceback names the exception as under ROS: rospy.exceptions, not minros.exceptions."""
    script = tmp_path / "endless.py"
    script.write_text(ENDLESS_LOOP)
    status, out = ctrl_c(script, ros_env(minros_core, ros_home))
    assert status == 1, out
    assert out.rstrip().splitlines()[-1] == \
        "rospy.exceptions.ROSInterruptException: ROS shutdown request"
    assert "minros.exceptions" not in out


def run(argv: List[str], env: Dict[str, str] | None = None, cwd: Path | None = None,
        timeout: float = 60) -> subprocess.CompletedProcess:
    return subprocess.run(argv, env=env, cwd=cwd, capture_output=True, text=True,
                          timeout=timeout)


def test_minros_version():
    done = run([str(VENV_BIN / "minros"), "--version"])
    assert done.returncode == 0, done.stderr
    where = Path(minros.__file__).resolve().parent
    assert re.fullmatch(rf"minros {re.escape(minros.__version__)} from {re.escape(str(where))} "
                        r"\(Python 3\.\d+\.\d+\S*, ROS 1 noetic\)\n", done.stdout), done.stdout
    # one version: the package's, the installed distribution's (pyproject.toml)
    assert importlib.metadata.version("minros") == minros.__version__
    assert "'minros --version'" in run([str(VENV_BIN / "minros"), "--help"]).stdout


def test_rosbag_help_offers_only_what_exists():
    done = run([str(VENV_BIN / "rosbag"), "--help"])
    assert done.returncode == 0
    assert "encrypt" not in done.stdout and "decrypt" not in done.stdout, done.stdout
    assert re.search(r"^   record  \tRecord a bag file", done.stdout, re.M)
    for argv, fix in ((["encrypt", "x.bag"], "use ROS's rosbag encrypt"),
                      (["decrypt", "-h"], "decrypt the bag with ROS's rosbag decrypt first")):
        gone = run([str(VENV_BIN / "rosbag"), *argv])
        assert gone.returncode == 1 and gone.stdout == "", gone
        assert gone.stderr.startswith(f"ERROR: rosbag {argv[0]} is not available in minros")
        assert fix in gone.stderr and gone.stderr.count("\n") == 1, gone.stderr


def test_minros_ws_help_explains_its_commands(tmp_path):
    done = run([str(VENV_BIN / "minros"), "ws", "--help"])
    assert done.returncode == 0, done.stderr
    text = done.stdout
    assert text.startswith("usage: minros ws {init,create_pkg,make} ...\n")
    for command, ros_name in (("init", "catkin_init_workspace"),
                              ("create_pkg", "catkin_create_pkg"), ("make", "catkin_make")):
        assert re.search(rf"^  {command} ", text, re.M) and f"({ros_name})" in text, text
    assert "minros ws create_pkg my_package rospy std_msgs" in text
    # the example it gives works
    src = tmp_path / "catkin_ws" / "src"
    src.mkdir(parents=True)
    for argv in (["init"], ["create_pkg", "my_package", "rospy", "std_msgs"]):
        step = run([str(VENV_BIN / "minros"), "ws", *argv], cwd=src)
        assert step.returncode == 0, step.stderr
    assert (src / "CMakeLists.txt").exists() and (src / "my_package" / "package.xml").exists()
    wrong = run([str(VENV_BIN / "minros"), "ws", "build"])
    assert wrong.returncode == 2 and "unknown command 'build'" in wrong.stderr
    assert "'minros ws --help' explains them" in wrong.stderr


BAD_URI = "ERROR: ROS_MASTER_URI is 'localhost:11311', which is not a master URI (it lacks the " \
          "scheme http://): set ROS_MASTER_URI=http://localhost:11311\n"


@pytest.mark.parametrize("argv", [
    ["rostopic", "list"], ["rostopic", "echo", "/chatter"], ["rosnode", "list"],
    ["rosparam", "get", "/x"], ["rosservice", "list"], ["rosbag", "record", "-a"],
    ["roslaunch", "turtlesim", "multisim.launch"], ["roscore"], ["rqt_graph", "-o", "g.png"],
    ["minros", "web"], ["minros", "sim"]], ids=lambda argv: " ".join(argv[:2]))
def test_a_master_uri_without_scheme_is_named_by_every_tool(argv, ros_home, tmp_path):
    env = ros_env(None, ros_home, {"ROS_MASTER_URI": "localhost:11311"})
    done = run([str(VENV_BIN / argv[0]), *argv[1:]], env=env, cwd=tmp_path, timeout=30)
    assert done.returncode == 1, done
    # rosbag keeps its own prefix for what stops the recorder
    assert done.stderr.replace("[FATAL] ", "ERROR: ") == BAD_URI, done.stderr
    assert "Traceback" not in done.stdout + done.stderr


def test_a_master_uri_without_scheme_ends_init_node_at_once(ros_home, tmp_path):
    """A rospy script: init_node raises ROSInitException at once, its last line the value and
    the fix (it waited forever before, as Debian's rospy does, which says "Failed to
    initialize time")."""
    script = tmp_path / "node.py"
    script.write_text("import rospy\n"
                      "try:\n"
                      "    rospy.init_node('x')\n"
                      "except rospy.ROSInitException as exc:\n"
                      "    print('caught:', exc)\n"
                      "    raise\n")
    env = ros_env(None, ros_home, {"ROS_MASTER_URI": "localhost:11311"})
    began = time.monotonic()
    done = run([PYTHON, str(script)], env=env, timeout=30)
    assert time.monotonic() - began < 20
    assert done.returncode == 1
    assert done.stdout == "caught: " + BAD_URI[len("ERROR: "):]
    assert done.stderr.rstrip().splitlines()[-1] == \
        "minros.rosenv.MasterURIError: " + BAD_URI[len("ERROR: "):].rstrip()
