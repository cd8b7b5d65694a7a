"""The seed tutorials followed literally, in bash, in a temporary HOME.

Each "terminal" of a document is one bash process; commands are the documents' commands in
their order, with the scanning damage read past (``catkin create pkg my package`` is
``catkin_create_pkg my_package``, ``Source devel/setup.bash`` is ``source``, ``std msgs`` is
``std_msgs``) and the missing commands of numbered steps filled in with the obvious one
("Navigate to the src directory" is ``cd ~/catkin_ws/src``). Two deliberate substitutions keep
the test hermetic: the master runs on a free port (``roscore -p PORT`` and ROS_MASTER_URI set as
a user with another port would), and seed 002's ``/any_name_ws`` lives in a temporary folder.
The seed publisher/subscriber scripts are the repaired copies in ``examples/pubsub/``.
"""

from __future__ import annotations

import re
import subprocess
import sys
from pathlib import Path

import pytest

from support import EXAMPLES, Proc, free_port, wait_for_master

SEED_SCRIPTS = EXAMPLES / "pubsub"
VENV_BIN = str(Path(sys.executable).parent)


class Desk:
    """A user's desk: a HOME, an environment, and terminals (bash processes) to type into."""

    def __init__(self, home: Path, port: int) -> None:
        self.home = home
        self.port = port
        self.env = {
            "HOME": str(home),
            # minros installed with pip into a venv that is on PATH; no ROS variables set
            "PATH": f"{VENV_BIN}:/usr/bin:/bin",
            "ROS_MASTER_URI": f"http://localhost:{port}",
            "ROS_HOSTNAME": "localhost",
            "PYTHONUNBUFFERED": "1",
            "LANG": "C.UTF-8",
        }
        self.terminals: list = []

    def type(self, commands: str, timeout: float = 60) -> str:
        """Run commands in a fresh terminal and wait; fail with its output if one fails."""
        result = subprocess.run(["bash", "-e", "-c", commands], cwd=self.home, env=self.env,
                                capture_output=True, text=True, timeout=timeout)
        assert result.returncode == 0, f"commands failed:\n{commands}\n{result.stdout}\n{result.stderr}"
        return result.stdout + result.stderr

    def open(self, commands: str) -> Proc:
        """A terminal left running (roscore, a node)."""
        proc = Proc(["bash", "-c", commands], self.env, cwd=self.home)
        self.terminals.append(proc)
        return proc

    def close_all(self) -> str:
        return "".join(t.stop() for t in reversed(self.terminals))


@pytest.fixture
def desk(tmp_path: Path):
    home = tmp_path / "home"
    home.mkdir()
    d = Desk(home, free_port())
    yield d
    d.close_all()


def _seed_script(name: str) -> str:
    return (SEED_SCRIPTS / name).read_text()


def _heredoc(path: str, text: str) -> str:
    return f"cat > {path} <<'SEED_EOF'\n{text}SEED_EOF\n"


WORKSPACE_000 = """
mkdir -p ~/catkin_ws/src
cd ~/catkin_ws/src
catkin_init_workspace
cd ~/catkin_ws
catkin_make
"""


def test_seed000_workspace_python_file_rosrun_and_roslaunch(desk: Desk):
    # "Workspace": steps 2-7
    out = desk.type(WORKSPACE_000)
    assert "Creating symlink" in out and "Base path:" in out
    ws = desk.home / "catkin_ws"
    assert (ws / "src" / "CMakeLists.txt").exists()
    assert (ws / "build").is_dir() and (ws / "devel" / "setup.bash").is_file()
    # "Python File in ROS workspace": steps 1-9
    python_file = "#!/usr/bin/env python\nimport rospy\nprint('python_file.py ran with rospy from', rospy.__name__)\n"
    out = desk.type(
        "cd ~/catkin_ws\n"
        "cd src\n"
        "catkin_create_pkg my_package rospy\n"
        "cd my_package\n"
        + _heredoc("python_file.py", python_file)
        + "chmod +x python_file.py\n"
        "source ~/catkin_ws/devel/setup.bash\n"
        "rosrun my_package python_file.py\n")
    assert "Created file my_package/package.xml" in out
    assert "python_file.py ran with rospy from rospy" in out
    # step 10: a launch file for it, started with roslaunch (which starts a master itself)
    launch = ('<launch>\n  <node pkg="my_package" type="python_file.py" name="python_file" '
              'output="screen"/>\n</launch>\n')
    desk.type("mkdir -p ~/catkin_ws/src/my_package/launch\n"
              + _heredoc("~/catkin_ws/src/my_package/launch/python_launch_file.launch", launch))
    term = desk.open("source ~/catkin_ws/devel/setup.bash\n"
                     "roslaunch my_package python_launch_file.launch\n")
    out = term.read_until("process has finished cleanly", timeout=30)
    out += term.stop()
    assert "python_file (my_package/python_file.py)" in out
    assert "python_file.py ran with rospy from rospy" in out
    assert "auto-starting new master" in out and out.rstrip().endswith("done")


def _pubsub(desk: Desk, pub_terminal: str, sub_terminal: str, heard: str) -> str:
    core = desk.open(f"roscore -p {desk.port}\n")
    wait_for_master(desk.port, timeout=20)
    assert core.alive()
    desk.open(pub_terminal)
    sub = desk.open(sub_terminal)
    out = sub.read_until("I heard", timeout=30)
    out += sub.read_until("I heard", timeout=10)
    assert len(re.findall(heard, out)) >= 2, out
    return out


def test_seed000_publisher_and_subscriber(desk: Desk):
    desk.type(WORKSPACE_000)
    # "Publisher and Subscriber": steps 1-8 (the package is created in the workspace's src)
    desk.type(
        "cd ~/catkin_ws/src\n"
        "catkin_create_pkg my_package rospy\n"
        "mkdir -p my_package/scripts\n"
        + _heredoc("my_package/scripts/my_publisher.py", _seed_script("my_publisher.py"))
        + "cd my_package/scripts\n"
        "chmod +x my_publisher.py\n"
        "cd ../..\n"
        + _heredoc("my_package/scripts/my_subscriber.py", _seed_script("my_subscriber.py"))
        + "cd my_package/scripts\n"
        "chmod +x my_subscriber.py\n"
        "cd ~/catkin_ws\n"
        "catkin_make\n")
    # steps 9-12: new terminals, each sources the workspace and runs one node
    out = _pubsub(
        desk,
        "cd ~/catkin_ws\nsource devel/setup.bash\nrosrun my_package my_publisher.py\n",
        "cd ~/catkin_ws\nsource devel/setup.bash\nrosrun my_package my_subscriber.py\n",
        r"/my_subscriber_\d+_\d+I heard Hello ROS!")
    assert "Traceback" not in out


def test_seed001_first_ros_node(desk: Desk):
    desk.type(WORKSPACE_000)
    desk.type(
        "cd ~/catkin_ws/src\n"
        "catkin_create_pkg my_package rospy roscpp std_msgs\n"
        + _heredoc("my_package/src/publisher.py", _seed_script("publisher.py"))
        + _heredoc("my_package/src/subscriber.py", _seed_script("subscriber.py"))
        + "chmod +x ~/catkin_ws/src/my_package/src/publisher.py\n"
        "chmod +x ~/catkin_ws/src/my_package/src/subscriber.py\n")
    assert (desk.home / "catkin_ws/src/my_package/include/my_package").is_dir()
    _pubsub(desk,
            "source ~/catkin_ws/devel/setup.bash\nrosrun my_package publisher.py\n",
            "source ~/catkin_ws/devel/setup.bash\nrosrun my_package subscriber.py\n",
            r"/subscriber_\d+_\d+I heard hello world \d+\.\d+")


# Seed 002's mypkg (cloned from GitHub in the blog; its scripts are only shown as pictures):
# a talker publishing "Hey There!! <time>" on chatter and a listener printing "I heard ...".
TASK0_PUB = """#!/usr/bin/env python
import rospy
from std_msgs.msg import String

def talker():
    pub = rospy.Publisher('chatter', String, queue_size=10)
    rospy.init_node('talker', anonymous=True)
    rate = rospy.Rate(10)
    while not rospy.is_shutdown():
        pub.publish("Hey There!! %s" % rospy.get_time())
        rate.sleep()

if __name__ == '__main__':
    try:
        talker()
    except rospy.ROSInterruptException:
        pass
"""

TASK0_SUB = """#!/usr/bin/env python
import rospy
from std_msgs.msg import String

def callback(data):
    rospy.loginfo("I heard %s", data.data)

def listener():
    rospy.init_node('listener', anonymous=True)
    rospy.Subscriber('chatter', String, callback)
    rospy.spin()

if __name__ == '__main__':
    listener()
"""


def test_seed002_any_name_ws(desk: Desk, tmp_path: Path):
    root = tmp_path / "root"  # stands for "/"
    root.mkdir()
    ws = f"{root}/any_name_ws"
    desk.type(
        'echo "source /opt/ros/kinetic/setup.bash" >> ~/.bashrc\n'
        f"mkdir -p {ws}/src\n"
        f"cd {ws}/src\n"
        "catkin_init_workspace\n"
        "cd ../\n"
        "catkin_make\n"
        f'echo "source {ws}/devel/setup.bash" >> ~/.bashrc\n'
        f"cd {ws}/src\n"
        # git clone https://github.com/Deeparaj-24/mypkg (no network here: the same package made locally)
        "catkin_create_pkg mypkg rospy std_msgs\n"
        "mkdir -p mypkg/scripts\n"
        + _heredoc("mypkg/scripts/task0_pub.py", TASK0_PUB)
        + _heredoc("mypkg/scripts/task0_sub.py", TASK0_SUB)
        # the seed's chmod, done before either terminal runs a script (in the publisher's
        # shell it raced the subscriber's rosrun, which then found the script not executable)
        + "chmod +x mypkg/scripts/task0_pub.py mypkg/scripts/task0_sub.py\n"
        "cd ../\n"
        "catkin_make\n")
    # new shells read ~/.bashrc (its kinetic line fails, as it would on a machine without it)
    new_shell = "source ~/.bashrc 2>/dev/null\n"
    pub = new_shell + f"cd {ws}/src/mypkg/scripts\nrosrun mypkg task0_pub.py\n"
    _pubsub(desk, pub, new_shell + "rosrun mypkg task0_sub.py\n", r"I heard Hey There!! \d+\.\d+")


MSG_PUB = """#!/usr/bin/env python
import rospy
from my_package.msg import Num

rospy.init_node('num_talker')
pub = rospy.Publisher('numbers', Num, queue_size=10)
rate = rospy.Rate(20)
i = 0
while not rospy.is_shutdown():
    pub.publish(Num(num=i, label="n%d" % i))
    i += 1
    rate.sleep()
"""

MSG_SUB = """#!/usr/bin/env python
import rospy
from my_package.msg import Num

def callback(msg):
    print("got %s %d %s" % (msg._type, msg.num, msg.label), flush=True)

rospy.init_node('num_listener')
rospy.Subscriber('numbers', Num, callback)
rospy.spin()
"""


def test_custom_message_in_workspace_package(desk: Desk):
    """ROS tutorial "Creating a ROS msg": msg/Num.msg, package.xml and CMakeLists edits,
    catkin_make, then two rosrun nodes exchanging the new type."""
    desk.type(WORKSPACE_000)
    desk.type(
        "cd ~/catkin_ws/src\n"
        "catkin_create_pkg my_package rospy std_msgs\n"
        "cd my_package\n"
        "mkdir msg\n"
        'echo "int64 num" > msg/Num.msg\n'
        'echo "string label" >> msg/Num.msg\n'
        "sed -i 's|<buildtool_depend>catkin</buildtool_depend>|&\\n  <build_depend>message_generation</build_depend>\\n"
        "  <exec_depend>message_runtime</exec_depend>|' package.xml\n"
        "sed -i 's|# add_message_files(FILES Message1.msg)|add_message_files(FILES Num.msg)|' CMakeLists.txt\n"
        "mkdir scripts\n"
        + _heredoc("scripts/num_talker.py", MSG_PUB)
        + _heredoc("scripts/num_listener.py", MSG_SUB)
        + "chmod +x scripts/*.py\n"
        "cd ~/catkin_ws\n"
        "catkin_make\n")
    assert "message_generation" in (desk.home / "catkin_ws/src/my_package/package.xml").read_text()
    shown = desk.type("source ~/catkin_ws/devel/setup.bash\nrosmsg show my_package/Num\n")
    assert shown.split() == ["int64", "num", "string", "label"]
    core = desk.open(f"roscore -p {desk.port}\n")
    wait_for_master(desk.port, timeout=20)
    assert core.alive()
    desk.open("source ~/catkin_ws/devel/setup.bash\nrosrun my_package num_talker.py\n")
    sub = desk.open("source ~/catkin_ws/devel/setup.bash\nrosrun my_package num_listener.py\n")
    out = sub.read_until("got my_package/Num", timeout=30)
    line = next(ln for ln in out.splitlines() if ln.startswith("got "))
    _got, msg_type, num, label = line.split()
    assert msg_type == "my_package/Num" and label == f"n{num}"
    # and the command-line tools see the workspace's type too
    echoed = desk.type("source ~/catkin_ws/devel/setup.bash\nrostopic echo -n 1 /numbers\n", timeout=30)
    fields = dict(ln.split(": ", 1) for ln in echoed.splitlines() if ": " in ln)
    assert int(fields["num"]) >= 0 and fields["label"].strip('"') == f"n{fields['num']}"
    assert "---" in echoed
