"""ROS tutorial "Writing a Simple Service and Client (Python)": rospy_tutorials' add_two_ints
server and client, unmodified (examples/add_two_ints/), on minros's master."""

from __future__ import annotations

import re
import subprocess
from pathlib import Path

import pytest

from support import EXAMPLES, PYTHON, Proc, ros_env

SCRIPTS = EXAMPLES / "add_two_ints"
SERVER = SCRIPTS / "add_two_ints_server.py"
CLIENT = SCRIPTS / "add_two_ints_client.py"


@pytest.fixture
def server(minros_master: int, ros_home: Path):
    env = ros_env(minros_master, ros_home)
    proc = Proc([PYTHON, str(SERVER)], env)
    yield proc, env
    proc.stop()


def run_client(env, *args: str, timeout: float = 30) -> subprocess.CompletedProcess:
    return subprocess.run([PYTHON, str(CLIENT), *args], env=env, capture_output=True, text=True,
                          timeout=timeout)


@pytest.mark.smoke
def test_client_prints_sum_and_server_prints_returning(server):
    proc, env = server
    done = run_client(env, "4", "5")
    assert done.returncode == 0, done.stderr
    assert done.stdout.splitlines() == ["Requesting 4+5", "4 + 5 = 9"]
    # the client calls twice: simplified style proxy(x, y), then formal proxy.call(Request)
    # (both answers were printed before the client got them back, so stopping now loses nothing)
    assert proc.stop().count("Returning [4 + 5 = 9]") == 2


def test_client_without_arguments_adds_random_numbers(server):
    _, env = server
    done = run_client(env)
    assert done.returncode == 0, done.stderr
    m = re.fullmatch(r"Requesting (-?\d+)\+(-?\d+)\n(-?\d+) \+ (-?\d+) = (-?\d+)\n", done.stdout)
    assert m, done.stdout
    x, y, x2, y2, total = map(int, m.groups())
    assert (x, y) == (x2, y2) and total == x + y


def test_client_strips_remapping_args_and_server_honours_them(minros_master, ros_home, monkeypatch):
    env = ros_env(minros_master, ros_home)
    # myargv() leaves "1 2" as the client's only arguments
    plain = Proc([PYTHON, str(SERVER)], env)
    try:
        done = run_client(env, "1", "2", "_rate:=5", "__name:=adder_client")
        assert done.returncode == 0, done.stderr
        assert done.stdout.splitlines()[-1] == "1 + 2 = 3"
    finally:
        plain.stop()
    # a remapped server offers /sum instead of /add_two_ints
    remapped = Proc([PYTHON, str(SERVER), "add_two_ints:=/sum"], env)
    try:
        import minros
        from rospy_tutorials.srv import AddTwoInts

        monkeypatch.setenv("ROS_MASTER_URI", env["ROS_MASTER_URI"])
        minros.wait_for_service("/sum", timeout=20)
        assert minros.ServiceProxy("/sum", AddTwoInts)(20, 22).sum == 42
    finally:
        out = remapped.stop()
    assert "Returning [20 + 22 = 42]" in out


def test_client_usage_on_bad_arguments(minros_master, ros_home):
    env = ros_env(minros_master, ros_home)
    done = run_client(env, "1")
    assert done.returncode == 1
    assert done.stdout.strip() == f"{CLIENT} [x y]"
    done = run_client(env, "one", "two")
    assert done.returncode == 1 and done.stdout.strip().endswith("[x y]")
