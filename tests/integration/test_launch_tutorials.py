"""The ROS tutorials' launch files run with minros's turtlesim (headless)."""

from __future__ import annotations

import sys
import xmlrpc.client
from pathlib import Path

import pytest

from support import Proc, free_port, ros_env, wait_until

pytest.importorskip("minros.nodes.turtlesim.turtlesim_node")

BIN = Path(sys.executable).parent
LAUNCH_FILES = Path(__file__).resolve().parent.parent / "unit" / "launch_files"


def _state(port: int):
    code, _msg, state = xmlrpc.client.ServerProxy(f"http://127.0.0.1:{port}/").getSystemState("/test")
    assert code == 1
    publishers, subscribers, services = ({topic: set(nodes) for topic, nodes in part} for part in state)
    return publishers, subscribers, services


def test_turtlemimic_launch_wires_the_mimic_between_two_turtlesims(tmp_path):
    port = free_port()
    env = ros_env(port, tmp_path / "home", {"MINROS_HEADLESS": "1"})
    proc = Proc([str(BIN / "roslaunch"), str(LAUNCH_FILES / "turtlemimic.launch"), "-p", str(port)], env)
    try:
        def wired():
            try:
                pubs, subs, srvs = _state(port)
            except OSError:
                return False
            return ("/mimic" in subs.get("/turtlesim1/turtle1/pose", set())
                    and "/mimic" in pubs.get("/turtlesim2/turtle1/cmd_vel", set())
                    and "/turtlesim1/sim" in pubs.get("/turtlesim1/turtle1/pose", set())
                    and "/turtlesim2/sim" in subs.get("/turtlesim2/turtle1/cmd_vel", set())
                    and "/turtlesim1/sim" in srvs.get("/turtlesim1/spawn", set()))
        wait_until(wired, timeout=30, what="turtlemimic graph")
    finally:
        out = proc.stop()
    for name in ("turtlesim1/sim-1", "turtlesim2/sim-2", "mimic-3"):
        assert f"process[{name}]: started with pid" in out
        assert f"[{name}] killing on exit" in out


@pytest.mark.smoke
def test_multisim_launch_starts_two_turtlesims(tmp_path):
    port = free_port()
    env = ros_env(port, tmp_path / "home", {"MINROS_HEADLESS": "1"})
    # turtlesim's own launch file, shipped with minros's built-in turtlesim package
    proc = Proc([str(BIN / "roslaunch"), "turtlesim", "multisim.launch", "-p", str(port)], env)
    try:
        def both():
            try:
                _pubs, _subs, srvs = _state(port)
            except OSError:
                return False
            return {"/turtlesim1/turtlesim", "/turtlesim2/turtlesim"} <= set().union(
                srvs.get("/turtlesim1/clear", set()), srvs.get("/turtlesim2/clear", set()))
        wait_until(both, timeout=30, what="two turtlesim nodes")
    finally:
        proc.stop()
