"""roslaunch's process API (pmon, nodeprocess, launch, server, child, parent) over minros:
the monitor's run loop on real processes, stop escalation, the parent/child XML-RPC API."""

from __future__ import annotations

import os
import signal
import sys
import threading
import time
import xmlrpc.client
from pathlib import Path

import pytest

import roslaunch.config
import roslaunch.core
import roslaunch.launch
import roslaunch.nodeprocess
import roslaunch.pmon
import roslaunch.server


@pytest.fixture(autouse=True)
def _ros_home(tmp_path: Path, monkeypatch: pytest.MonkeyPatch):
    monkeypatch.setenv("ROS_HOME", str(tmp_path))
    monkeypatch.setenv("ROS_LOG_DIR", str(tmp_path / "log"))
    yield
    roslaunch.core.clear_printlog_handlers()
    roslaunch.core.clear_printerrlog_handlers()


def _local(name: str, code: str, **kwargs) -> roslaunch.nodeprocess.LocalProcess:
    return roslaunch.nodeprocess.LocalProcess("run-1", "pkg", name, [sys.executable, "-c", code],
                                              dict(os.environ), True, is_node=False, **kwargs)


def _run_monitor(pm: roslaunch.pmon.ProcessMonitor, limit: float = 10.0) -> None:
    killer = threading.Timer(limit, pm.shutdown)
    killer.start()
    try:
        pm.run()
    finally:
        killer.cancel()


@pytest.mark.slow
def test_monitor_respawns_reports_and_ends_when_all_are_gone(capsys):
    pm = roslaunch.pmon.ProcessMonitor()
    quick = _local("quick", "raise SystemExit(3)")
    again = _local("again", "pass", respawn=True, respawn_delay=0.2)
    died = []

    class Listener(roslaunch.pmon.ProcessListener):
        def process_died(self, name, code):
            died.append((name, code))
            if name == "again" and again.spawn_count >= 2:
                again.respawn = False  # the second death is final

    pm.add_process_listener(Listener())
    for p in (quick, again):
        pm.register(p)
        p.start()
    pm.registrations_complete()
    started = time.monotonic()
    _run_monitor(pm)
    assert pm.done and pm.is_shutdown and not pm.procs
    assert ("quick", 3) in died and again.spawn_count == 2
    assert time.monotonic() - started >= 0.2  # the respawn delay was kept
    alive, dead = pm.get_process_names_with_spawn_count()
    assert alive == [] and sorted(dead) == [("again", 2), ("quick", 1)]
    err = capsys.readouterr()
    assert "[quick] process has died [pid" in err.err and "exit code 3" in err.err
    assert "all processes on machine have died, roslaunch will exit" in err.out
    assert "log file: " in err.err and quick.log_dir and os.path.isdir(quick.log_dir)


@pytest.mark.slow
def test_required_process_death_shuts_the_monitor_down(capsys):
    pm = roslaunch.pmon.ProcessMonitor()
    keeper = _local("keeper", "import time; time.sleep(30)")
    boss = _local("boss", "pass", required=True)
    for p in (keeper, boss):
        pm.register(p)
        p.start()
    _run_monitor(pm)
    assert "REQUIRED process [boss] has died!" in capsys.readouterr().err
    assert not keeper.is_alive()  # stopped on the monitor's exit


@pytest.mark.slow
def test_stop_escalates_from_sigint_to_sigterm_on_time():
    code = ("import signal, time, sys; signal.signal(signal.SIGINT, signal.SIG_IGN); "
            "print('up', flush=True); time.sleep(30)")
    p = _local("stubborn", code, sigint_timeout=0.5, sigterm_timeout=2.0)
    assert p.start() and p.is_alive()
    time.sleep(0.5)
    errors: list = []
    started = time.monotonic()
    p.stop(errors)
    took = time.monotonic() - started
    assert 0.4 < took < 2.0 and errors == []  # SIGTERM ended it, no SIGKILL needed
    assert p.exit_code == -signal.SIGTERM and not p.is_alive()
    with pytest.raises(roslaunch.core.RLException, match="sigint_timeout must be a positive"):
        _local("x", "pass", sigint_timeout=0)


def test_master_and_node_processes_are_roslaunchs():
    m = roslaunch.nodeprocess.create_master_process("r", roslaunch.core.Master.ROSMASTER, None, 11399)
    assert m.args == ["rosmaster", "--core", "-p", "11399", "-w", "3"] and m.required
    with pytest.raises(roslaunch.core.RLException, match="invalid port assignment"):
        roslaunch.nodeprocess.create_master_process("r", "rosmaster", None, 0)
    node = roslaunch.core.Node("rospy_tutorials", "talker", name="t", namespace="/ns",
                               args="--x $(env HOME)", remap_args=[("a", "b")])
    with pytest.raises(roslaunch.core.RLException, match="no machine selected"):
        roslaunch.nodeprocess.create_node_process("r", node, "http://localhost:1/")
    node.machine = roslaunch.core.local_machine()
    p = roslaunch.nodeprocess.create_node_process("r", node, "http://localhost:1/")
    assert p.name.startswith("ns/t-") and p.env["ROS_NAMESPACE"] == "/ns"
    assert p.args[-4:] == ["--x", os.environ["HOME"], "a:=b", "__name:=t"] and p.log_output
    missing = roslaunch.core.Node("rospy_tutorials", "no_such_node", name="n")
    missing.machine = node.machine
    from roslaunch.node_args import NodeParamsException

    with pytest.raises(NodeParamsException, match=r"^Cannot locate node of type \[no_such_node\]"):
        roslaunch.nodeprocess.create_node_process("r", missing, "http://localhost:1/")


def test_parent_and_child_servers_register_and_launch():
    pm = roslaunch.pmon.ProcessMonitor()
    parent = roslaunch.server.ROSLaunchParentNode(roslaunch.config.ROSLaunchConfig(), pm)
    parent.add_child("child-1", roslaunch.server.ChildROSLaunchProcess("child-1", [], {}))
    parent.start()
    child = None
    try:
        server = xmlrpc.client.ServerProxy(parent.uri)
        assert server.get_pid() == [1, str(os.getpid()), os.getpid()]
        assert server.register("stranger", "http://x:1/")[0] == -1
        child = roslaunch.server.ROSLaunchChildNode("run-1", "child-1", parent.uri,
                                                    roslaunch.pmon.start_process_monitor())
        child.start()
        assert server.list_children() == [1, "roslaunch children", [child.uri]]
        code, _msg, _ = xmlrpc.client.ServerProxy(child.uri).launch("<launch><bad")
        assert code == -1
    finally:
        if child is not None:
            child.shutdown("done")
        parent.shutdown("done")


def test_launch_helpers(monkeypatch: pytest.MonkeyPatch):
    assert roslaunch.launch._unify_clear_params(["/a", "/a/b", "/c/"]) == ["/a/", "/c/"]
    assert roslaunch.launch._hostname_to_rosname("My-Host.1") == "host_my_host_1"
    said: list = []
    monkeypatch.setenv("ROS_MASTER_URI", "http://localhost:11311")
    monkeypatch.setattr(roslaunch.launch, "printerrlog", said.append)  # the stand-in is the module
    roslaunch.launch.validate_master_launch(roslaunch.core.Master(uri="http://localhost:9/"), True)
    assert said == ["WARNING: ROS_MASTER_URI port [11311] does not match this roscore [9]"]


def test_runner_reads_each_answer_of_a_parameter_multicall():
    """system.multicall answers each call as [triplet], or a fault struct: the launch stops at
    the first that is no success and names it."""
    from minros.launch.rosmodel import RLException
    from minros.launch.rosrunner import _check_all

    _check_all([[[1, "parameter /a set", 0]], [[1, "parameter /b set", 0]]], "Failed")
    with pytest.raises(RLException, match=r"^Failed to set parameter: cannot set /b$"):
        _check_all([[[1, "", 0]], [[-1, "cannot set /b", 0]]], "Failed to set parameter")
    with pytest.raises(RLException, match=r"^Failed: boom$"):
        _check_all([{"faultCode": 1, "faultString": "boom"}], "Failed")
