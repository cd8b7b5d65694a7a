"""bondpy and nodelet against Debian's: bonds between a minros process and a Debian bondpy
process form and break both ways (a clean break, and a killed sister noticed by its missing
heartbeats); Debian's C++ `nodelet load` loads a Python nodelet into minros's manager (with
its remapping), and the manager unloads it when the loader is stopped or killed; our `nodelet
load` gets Debian's C++ manager's refusal of a type it does not know."""

from __future__ import annotations

import os
import signal
import subprocess
from pathlib import Path

import pytest
import yaml

from support import (
    PYTHON,
    REFERENCE_PYTHON,
    Proc,
    need,
    reference_env,
    reference_imports,
    ros_env,
    wait_until,
)

pytestmark = pytest.mark.interop

ROSRUN = str(Path(PYTHON).parent / "rosrun")
DEBIAN_NODELET = "/usr/lib/nodelet/nodelet"

BOND_SIDE = r'''
import sys, time
import rospy
from bondpy import bondpy
rospy.init_node(sys.argv[1])
bond = bondpy.Bond("/test_bond", "pair", on_formed=lambda: print("formed", flush=True),
                   on_broken=lambda: print("on_broken called", flush=True))
bond.heartbeat_timeout = 1.5
bond.heartbeat_period = 0.2
bond.start()
assert bond.wait_until_formed(rospy.Duration(20)), "never formed"
print("waited formed", flush=True)
if sys.argv[2] == "break":
    time.sleep(1.0)
    bond.break_bond()
    print("broke it", flush=True)
print("broken wait %s" % bond.wait_until_broken(rospy.Duration(20)), flush=True)
'''


@pytest.mark.parametrize("breaker", ["minros", "debian"])
def test_bonds_form_and_break_both_ways(tmp_path: Path, debian_rosmaster: int, ros_home: Path,
                                        breaker: str) -> None:
    need(reference_imports("bondpy.bondpy"), "Debian's python3-bondpy is not installed",
         "scripts/install-ros-reference.sh")
    script = tmp_path / "bond_side.py"
    script.write_text(BOND_SIDE)
    env = ros_env(debian_rosmaster, ros_home)
    mine = Proc([PYTHON, str(script), "mine", "break" if breaker == "minros" else "wait"], env)
    theirs = Proc([REFERENCE_PYTHON, str(script), "theirs",
                   "break" if breaker == "debian" else "wait"], reference_env(env))
    try:
        outs = {}
        for proc in (mine, theirs):
            outs[proc] = proc.read_until("broken wait", 40)
            assert "formed" in outs[proc] and "broken wait True" in outs[proc], outs[proc]
        waiter = theirs if breaker == "minros" else mine
        if "on_broken called" not in outs[waiter]:  # the callback runs after the wait ends
            waiter.read_until("on_broken called", 10)
    finally:
        mine.stop()
        theirs.stop()


def test_killed_sister_is_noticed_by_heartbeat_timeout(tmp_path: Path, debian_rosmaster: int,
                                                       ros_home: Path) -> None:
    need(reference_imports("bondpy.bondpy"), "Debian's python3-bondpy is not installed",
         "scripts/install-ros-reference.sh")
    script = tmp_path / "bond_side.py"
    script.write_text(BOND_SIDE)
    env = ros_env(debian_rosmaster, ros_home)
    mine = Proc([PYTHON, str(script), "mine", "wait"], env)
    theirs = Proc([REFERENCE_PYTHON, str(script), "theirs", "wait"], reference_env(env))
    try:
        mine.read_until("waited formed", 40)
        theirs.read_until("waited formed", 40)
        os.killpg(theirs.pid, signal.SIGKILL)
        out = mine.read_until("broken wait", 20)
        assert "broken wait True" in out, out + mine.stop()
    finally:
        mine.stop()
        theirs.stop()


PLUGINS = """<library path="lib/unused">
  <class name="pynodelets/Talker" type="pynodelets_impl.Talker" base_class_type="nodelet::Nodelet">
    <description>says hello on ~out (or what it is remapped to)</description>
  </class>
</library>
"""

PACKAGE = """<?xml version="1.0"?>
<package format="2">
  <name>pynodelets</name><version>0.0.1</version><description>test</description>
  <maintainer email="a@b.c">a</maintainer><license>BSD</license>
  <buildtool_depend>catkin</buildtool_depend>
  <export><nodelet plugin="${prefix}/nodelet_plugins.xml"/></export>
</package>
"""

IMPL = r'''
import minros as rospy
from std_msgs.msg import String
from minros.nodelet import Nodelet


class Talker(Nodelet):
    def onInit(self):
        topic = self.resolve_name("out")
        self.pub = rospy.Publisher(topic, String, queue_size=1, latch=True)
        self.pub.publish(String(data="hello from %s on %s args %s" % (
            self.getName(), topic, self.getMyArgv())))
        print("NODELET UP " + self.getName(), flush=True)

    def onShutdown(self):
        self.pub.unregister()
        print("NODELET DOWN " + self.getName(), flush=True)
'''


def _workspace(tmp_path: Path) -> dict:
    pkg = tmp_path / "ws" / "pynodelets"
    pkg.mkdir(parents=True)
    (pkg / "package.xml").write_text(PACKAGE)
    (pkg / "nodelet_plugins.xml").write_text(PLUGINS)
    lib = tmp_path / "lib"
    lib.mkdir()
    (lib / "pynodelets_impl.py").write_text(IMPL)
    return {"ROS_PACKAGE_PATH": str(tmp_path / "ws"), "PYTHONPATH": str(lib)}


def _list(env: dict, manager: str) -> list:
    done = subprocess.run(["/usr/bin/rosservice", "call", f"{manager}/list"], env=env,
                          capture_output=True, text=True, timeout=30)
    assert done.returncode == 0, done.stderr
    return yaml.safe_load(done.stdout)["nodelets"]


@pytest.mark.parametrize("stop_with", [signal.SIGINT, signal.SIGKILL])
def test_debian_loader_and_minros_manager(tmp_path: Path, debian_rosmaster: int, ros_home: Path,
                                          stop_with: int) -> None:
    need(os.access(DEBIAN_NODELET, os.X_OK), "Debian's nodelet program (libnodeletlib-tools) "
         "is not installed", "scripts/install-ros-reference.sh")
    env = ros_env(debian_rosmaster, ros_home, _workspace(tmp_path))
    denv = reference_env(ros_env(debian_rosmaster, ros_home))
    manager = Proc([ROSRUN, "nodelet", "nodelet", "manager", "__name:=mgr"], env)
    loader = None
    try:
        wait_until(lambda: subprocess.run(["/usr/bin/rosservice", "list"], env=denv,
                                          capture_output=True, text=True,
                                          timeout=30).stdout.count("/mgr/") >= 3, 30,
                   what="the manager's services")
        loader = Proc([DEBIAN_NODELET, "load", "pynodelets/Talker", "/mgr", "out:=/greeting",
                       "extra_arg", "__name:=talker1"], denv)
        manager.read_until("NODELET UP /talker1", 30)
        echo = subprocess.run(["/usr/bin/rostopic", "echo", "-n", "1", "/greeting"], env=denv,
                              capture_output=True, text=True, timeout=30)
        assert "hello from /talker1 on /greeting args ['extra_arg']" in echo.stdout, echo
        assert _list(denv, "/mgr") == ["/talker1"]
        os.killpg(loader.pid, stop_with)
        # SIGINT: the loader unloads it; SIGKILL: the manager sees the bond break (4 s)
        manager.read_until("NODELET DOWN /talker1", 20)
        assert _list(denv, "/mgr") == []
    finally:
        if loader is not None:
            loader.stop()
        manager.stop()


def test_minros_loader_gets_debian_managers_refusal(tmp_path: Path, debian_rosmaster: int,
                                                    ros_home: Path) -> None:
    need(os.access(DEBIAN_NODELET, os.X_OK), "Debian's nodelet program (libnodeletlib-tools) "
         "is not installed", "scripts/install-ros-reference.sh")
    env = ros_env(debian_rosmaster, ros_home)
    manager = Proc([DEBIAN_NODELET, "manager", "__name:=cppmgr"], reference_env(env))
    try:
        done = subprocess.run([ROSRUN, "nodelet", "nodelet", "load", "no_such/Type", "/cppmgr"],
                              env=env, capture_output=True, text=True, timeout=60)
        assert done.returncode != 0
        assert "Failed to load nodelet '/no_such_Type` of type `no_such/Type` to manager " \
               "`/cppmgr'" in done.stdout + done.stderr, done
    finally:
        manager.stop()
