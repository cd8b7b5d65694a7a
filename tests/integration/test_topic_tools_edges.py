"""topic_tools' programs where ROS's behave in a way a test or a launch file relies on:
invalid arguments end the program at once (non-zero, the usage text) instead of waiting for a
master; the mux refuses to add what it muxes already and to delete its selected input; relay's
lazy and stealth modes (ROS's relay.cpp: ``~lazy``, ``~stealth``, ``~monitor_topic``).

The invalid argument lists are ROS's own (tools/topic_tools/test/args.py); the interop test
below runs them through Debian's programs too, so the expectation is ROS's, not ours.
"""

from __future__ import annotations

import os
import subprocess
import textwrap
from pathlib import Path

import pytest

from support import PYTHON, Proc, free_port, need, reference_env, ros_env

ROSRUN = str(Path(PYTHON).parent / "rosrun")
DEBIAN_TOOLS = "/usr/lib/topic_tools"

INVALID = [
    ("drop", []), ("drop", ["//", "1", "2", "output"]),
    ("drop", ["input", "1", "2", "output", "extra"]), ("drop", ["input", "-1", "2", "output"]),
    ("drop", ["input", "1", "0", "output"]),
    ("mux", []), ("mux", ["//", "input"]),
    ("switch_mux", []), ("switch_mux", ["//", "input"]),
    ("relay", []), ("relay", ["//", "input"]),
]


def _dead_master_env(home: Path) -> dict:
    # a master URI nobody answers: a program that waited for one would hang here
    return ros_env(free_port(), home)


@pytest.mark.parametrize("program,args", INVALID, ids=[f"{p} {' '.join(a)}" for p, a in INVALID])
def test_invalid_arguments_end_the_program_before_it_waits_for_a_master(
        program: str, args: list, ros_home: Path):
    out = subprocess.run([ROSRUN, "topic_tools", program, *args], env=_dead_master_env(ros_home),
                         capture_output=True, text=True, timeout=20)
    assert out.returncode != 0
    text = out.stdout + out.stderr
    assert "usage: " in text, text
    assert "Traceback" not in text, text


@pytest.mark.interop
@pytest.mark.parametrize("program,args", INVALID, ids=[f"{p} {' '.join(a)}" for p, a in INVALID])
def test_debians_programs_refuse_the_same_arguments(program: str, args: list, ros_home: Path):
    need(os.access(f"{DEBIAN_TOOLS}/{program}", os.X_OK),
         "Debian's topic-tools programs are not installed", "scripts/install-ros-reference.sh")
    env = reference_env(_dead_master_env(ros_home))
    try:
        out = subprocess.run([f"{DEBIAN_TOOLS}/{program}", *args], env=env, capture_output=True,
                             text=True, timeout=20)
    except subprocess.TimeoutExpired:
        pytest.fail(f"Debian's {program} {args} waited: the expectation above is not ROS's")
    assert out.returncode != 0


def _call(env: dict, service: str, *args: str) -> subprocess.CompletedProcess:
    rosservice = str(Path(PYTHON).parent / "rosservice")
    return subprocess.run([rosservice, "call", "--wait", service, *args], env=env,
                          capture_output=True, text=True, timeout=30)


def test_mux_services_as_ros_test_mux_services_uses_them(minros_master: int, ros_home: Path):
    """ROS's test_mux_services.py sequence: add, add again (fails), delete the selected input
    (fails), select none, delete both."""
    env = ros_env(minros_master, ros_home)
    mux = Proc([ROSRUN, "topic_tools", "mux", "output", "input"], env)
    try:
        def topics() -> list:
            out = _call(env, "/mux/list")
            assert out.returncode == 0, out.stdout + out.stderr
            return sorted(line.strip("- ").strip() for line in out.stdout.splitlines()
                          if line.strip().startswith("-"))

        assert topics() == ["/input"]
        assert _call(env, "/mux/add", "/new_input").returncode == 0
        assert topics() == ["/input", "/new_input"]
        again = _call(env, "/mux/add", "/new_input")
        assert again.returncode != 0 and "already" in again.stdout + again.stderr
        assert _call(env, "/mux/add", "__none").returncode != 0
        assert topics() == ["/input", "/new_input"]
        assert _call(env, "/mux/select", "/input").returncode == 0
        selected = _call(env, "/mux/delete", "/input")
        assert selected.returncode != 0 and "selected" in selected.stdout + selected.stderr
        assert topics() == ["/input", "/new_input"]
        assert _call(env, "/mux/select", "__none").returncode == 0
        assert _call(env, "/mux/delete", "/input").returncode == 0
        assert topics() == ["/new_input"]
        # switch_mux selects through the mux's <output>_select service
        switch = subprocess.run([ROSRUN, "topic_tools", "switch_mux", "output", "/new_input"],
                                env=env, capture_output=True, text=True, timeout=30)
        assert switch.returncode == 0, switch.stdout + switch.stderr
    finally:
        mux.stop()


# Counts what reaches /stealth_out while /orig_relay (the monitored topic) has a subscriber of
# its own, and while it has none: a stealth relay forwards only in the first phase.
STEALTH_PROBE = textwrap.dedent(r"""
    import json, sys, threading, time
    import rospy
    from std_msgs.msg import String
    rospy.init_node("stealth_probe")
    out = []
    sub = rospy.Subscriber("/stealth_out", String, lambda m: out.append(time.monotonic()))
    deadline = time.monotonic() + 20
    while sub.get_num_connections() == 0 and time.monotonic() < deadline:
        time.sleep(0.05)
    phases = {"connected": sub.get_num_connections() > 0}
    time.sleep(1.5)
    phases["before_monitor"] = len(out)
    came = threading.Event()
    monitor = rospy.Subscriber("/orig_relay", String, lambda m: came.set())
    came.wait(10)
    start = len(out)
    deadline = time.monotonic() + 10
    while len(out) - start < 3 and time.monotonic() < deadline:
        time.sleep(0.05)
    phases["while_monitored"] = len(out) - start
    monitor.unregister()
    time.sleep(1.0)  # the relay checks its monitored topic every 0.2 s
    settled = len(out)
    time.sleep(1.5)
    phases["after_monitor"] = len(out) - settled
    print("PHASES " + json.dumps(phases), flush=True)
""")


def test_relay_lazy_and_stealth(minros_master: int, ros_home: Path, tmp_path: Path):
    env = ros_env(minros_master, ros_home)
    rostopic = str(Path(PYTHON).parent / "rostopic")
    probe = tmp_path / "probe.py"
    probe.write_text(STEALTH_PROBE)
    procs = [
        Proc([rostopic, "pub", "-r", "20", "/orig", "std_msgs/String", "foo"], env),
        # lazy: takes /orig only while /orig_relay has subscribers
        Proc([ROSRUN, "topic_tools", "relay", "/orig", "/orig_relay", "_lazy:=true"], env),
        Proc([ROSRUN, "topic_tools", "relay", "/orig_relay", "/stealth_out", "_stealth:=true",
              "_monitor_topic:=/orig_relay", "_monitor_rate:=0.2"], env),
    ]
    try:
        out = subprocess.run([PYTHON, str(probe)], env=env, capture_output=True, text=True,
                             timeout=60)
        line = next((x for x in out.stdout.splitlines() if x.startswith("PHASES ")), None)
        assert line, out.stdout + out.stderr
        import json

        phases = json.loads(line[len("PHASES "):])
        assert phases["connected"], phases
        assert phases["before_monitor"] == 0, phases  # its own subscriber does not wake it
        assert phases["while_monitored"] >= 3, phases
        assert phases["after_monitor"] <= 2, phases  # it let go of its input again
    finally:
        for proc in procs:
            proc.stop()
