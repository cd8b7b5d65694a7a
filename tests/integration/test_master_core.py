"""`minros core` and `python -m minros.master` as processes: output, parameters, rosout, ports,
signals, the shutdown API."""

from __future__ import annotations

import os
import re
import signal
import socket
import subprocess
import xmlrpc.client

import pytest

from support import PYTHON, Proc, free_port, ros_env, wait_for_master, wait_until


def master(port: int):
    return xmlrpc.client.ServerProxy(f"http://127.0.0.1:{port}/")


@pytest.fixture
def core(ros_home):
    port = free_port()
    proc = Proc([PYTHON, "-m", "minros", "core", "-p", str(port)], ros_env(port, ros_home))
    try:
        head = proc.read_until("started core service [/rosout]", timeout=20)
        yield port, proc, head
    finally:
        proc.stop()


def test_core_prints_summary_and_sets_roscore_params(core):
    port, _proc, head = core
    assert f"ROS_MASTER_URI=http://localhost:{port}/" in head
    assert " * /rosdistro: noetic" in head and "PARAMETERS" in head and "SUMMARY" in head
    run_id = master(port).getParam("/t", "/run_id")[2]
    assert re.fullmatch(r"[0-9a-f]{8}-[0-9a-f]{4}-1[0-9a-f]{3}-[0-9a-f]{4}-[0-9a-f]{12}", run_id)
    assert f"setting /run_id to {run_id}" in head
    assert master(port).getParam("/t", "/rosdistro")[2] == "noetic\n"
    # what `rosversion roslaunch` prints, as roscore.xml sets it: the ros_comm release spoken
    assert master(port).getParam("/t", "/rosversion")[2] == "1.15.15\n"
    assert " * /rosversion: 1.15.15" in head


def test_core_runs_rosout(core):
    port = core[0]

    def rosout_registered():
        pubs, subs, _srvs = master(port).getSystemState("/t")[2]
        return ["/rosout_agg", ["/rosout"]] in pubs and ["/rosout", ["/rosout"]] in subs

    wait_until(rosout_registered, timeout=20, what="rosout registered")
    assert master(port).lookupNode("/t", "/rosout")[0] == 1


def test_core_respawns_rosout(core):
    port, proc, head = core
    pid = int(re.search(r"process\[rosout-1\]: started with pid \[(\d+)\]", head).group(1))
    wait_until(lambda: master(port).lookupNode("/t", "/rosout")[0] == 1, 20, what="rosout up")
    os.kill(pid, signal.SIGKILL)
    proc.read_until("[rosout-1] restarting process", timeout=15)
    text = proc.read_until("process[rosout-1]: started with pid", timeout=15)
    new_pid = int(re.search(r"started with pid \[(\d+)\]", text).group(1))
    assert new_pid != pid

    def new_rosout():
        code, _msg, uri = master(port).lookupNode("/t", "/rosout")
        return code == 1 and master(port).getSystemState("/t")[2][0]

    wait_until(new_rosout, timeout=20, what="respawned rosout registered")


def test_core_sigterm_is_clean(core):
    _port, proc, head = core
    pid = int(re.search(r"process\[rosout-1\]: started with pid \[(\d+)\]", head).group(1))
    proc.popen.send_signal(signal.SIGTERM)
    assert proc.popen.wait(10) == 0
    out = proc.output()
    assert "Traceback" not in out and out.rstrip().endswith("done")
    wait_until(lambda: not _alive(pid), timeout=10, what="rosout stopped")


def _alive(pid: int) -> bool:
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    # a zombie is dead for our purpose
    try:
        with open(f"/proc/{pid}/stat") as f:
            return f.read().split()[2] != "Z"
    except OSError:
        return False


def test_core_port_from_ros_master_uri(ros_home):
    port = free_port()
    proc = Proc([PYTHON, "-m", "minros", "core", "--no-rosout"], ros_env(port, ros_home))
    try:
        wait_for_master(port)
        assert master(port).getUri("/t")[2] == f"http://localhost:{port}/"
    finally:
        proc.stop()


def test_core_host_option(ros_home):
    port = free_port()
    proc = Proc([PYTHON, "-m", "minros", "core", "--no-rosout", "-p", str(port), "--host",
                 "127.0.0.1"], ros_env(port, ros_home))
    try:
        wait_for_master(port)
        assert master(port).getUri("/t")[2] == f"http://127.0.0.1:{port}/"
    finally:
        proc.stop()


@pytest.mark.parametrize("argv", [["-m", "minros", "core"], ["-m", "minros.master"]])
def test_port_taken_is_one_line_and_nonzero(ros_home, argv):
    with socket.socket() as blocker:
        blocker.bind(("0.0.0.0", 0))
        blocker.listen()
        port = blocker.getsockname()[1]
        done = subprocess.run([PYTHON, *argv, "-p", str(port)], env=ros_env(port, ros_home),
                              capture_output=True, text=True, timeout=20)
    assert done.returncode != 0
    lines = done.stderr.strip().splitlines()
    assert len(lines) == 1 and str(port) in lines[0], done.stderr
    assert "Traceback" not in done.stdout + done.stderr


def test_core_refuses_to_start_beside_a_running_master(minros_master, ros_home):
    done = subprocess.run([PYTHON, "-m", "minros", "core", "-p", str(minros_master)],
                          env=ros_env(minros_master, ros_home), capture_output=True, text=True,
                          timeout=20)
    assert done.returncode == 1
    assert "already running" in done.stderr and len(done.stderr.strip().splitlines()) == 1


@pytest.mark.smoke
def test_shutdown_api_stops_the_master(ros_home):
    port = free_port()
    proc = Proc([PYTHON, "-m", "minros.master", "-p", str(port)], ros_env(port, ros_home))
    try:
        wait_for_master(port)
        assert master(port).shutdown("/t", "test over") == [1, "shutdown", 0]
        assert proc.popen.wait(10) == 0
        assert "shutdown request: test over" in proc.output()
    finally:
        proc.stop()


def test_bad_port_argument(ros_home):
    done = subprocess.run([PYTHON, "-m", "minros.master", "-p", "70000"],
                          env=ros_env(None, ros_home), capture_output=True, text=True, timeout=20)
    assert done.returncode == 2 and "invalid port" in done.stderr


def test_core_writes_master_log(core, ros_home):
    port = core[0]
    run_id = master(port).getParam("/t", "/run_id")[2]
    run_dir = ros_home / "log" / run_id
    log = run_dir / "master.log"
    wait_until(lambda: log.exists() and "+PUB [/rosout_agg] /rosout" in log.read_text(), 20,
               what="rosout's registration in master.log")
    assert "+PARAM [/run_id] by /roscore" in log.read_text()
    latest = ros_home / "log" / "latest"  # roscore's link to the newest run
    assert latest.is_symlink() and latest.resolve() == run_dir.resolve()


def test_rosout_exits_when_core_is_killed(core):
    _port, proc, head = core
    pid = int(re.search(r"process\[rosout-1\]: started with pid \[(\d+)\]", head).group(1))
    proc.popen.kill()  # SIGKILL to the core alone: no chance to stop its child
    proc.popen.wait(5)
    wait_until(lambda: not _alive(pid), timeout=15, what="orphaned rosout exiting")
