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
# its own, and while it has none: a stealth relay forwards only in the first phase. The relay's
# decisions are seen at the master (its subscription to /orig_relay, checked every 0.2 s:
# _monitor_rate); a phase that proves something does NOT happen watches for WINDOW, five of
# the relay's checks, failing at once when it happens (an absence has no event to wait for).
STEALTH_PROBE = textwrap.dedent(r"""
    import json, os, threading, time, xmlrpc.client
    import rospy
    from std_msgs.msg import String
    WINDOW = 5 * 0.2
    rospy.init_node("stealth_probe")
    me = rospy.get_name()
    master = xmlrpc.client.ServerProxy(os.environ["ROS_MASTER_URI"])

    def relay_subscribed():
        subs = master.getSystemState(me)[2][1]
        return any(node != me for topic, nodes in subs if topic == "/orig_relay" for node in nodes)

    def until(done, seconds):
        deadline = time.monotonic() + seconds
        while not done() and time.monotonic() < deadline:
            time.sleep(0.02)
        return done()

    out = []
    sub = rospy.Subscriber("/stealth_out", String, lambda m: out.append(time.monotonic()))
    phases = {"connected": until(lambda: sub.get_num_connections() > 0, 20)}
    # its own subscriber (this probe) does not wake it: it stays off /orig_relay for WINDOW
    phases["woke_before_monitor"] = until(lambda: out or relay_subscribed(), WINDOW)
    phases["before_monitor"] = len(out)
    came = threading.Event()
    monitor = rospy.Subscriber("/orig_relay", String, lambda m: came.set())
    phases["monitor_fed"] = came.wait(10)
    start = len(out)
    until(lambda: len(out) - start >= 3, 10)
    phases["while_monitored"] = len(out) - start
    monitor.unregister()
    # it lets go of its input at its next check; then nothing more comes through
    phases["let_go"] = until(lambda: not relay_subscribed(), 10)
    settled = len(out)
    until(lambda: len(out) - settled > 2, WINDOW)
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
        assert phases["connected"] and phases["monitor_fed"], phases
        assert not phases["woke_before_monitor"], phases  # its own subscriber does not wake it
        assert phases["before_monitor"] == 0, phases
        assert phases["while_monitored"] >= 3, phases
        assert phases["let_go"], phases  # it let go of its input again
        assert phases["after_monitor"] <= 2, phases  # at most what was in flight
    finally:
        for proc in procs:
            proc.stop()
