"""Debian's rostopic and rosnode against minros nodes (on Debian's rosmaster)."""

from __future__ import annotations

import re
import subprocess
from pathlib import Path

import pytest

from integration.pubsub_scripts import LISTENER, TALKER
from support import PYTHON, Proc, reference_env, require_reference, ros_env, wait_until

pytestmark = pytest.mark.interop


def _tool(port: int, home: Path, *argv: str, timeout: float = 20) -> subprocess.CompletedProcess:
    return subprocess.run([f"/usr/bin/{argv[0]}", *argv[1:]], env=reference_env(ros_env(port, home)),
                          capture_output=True, text=True, timeout=timeout)


@pytest.fixture
def talker(tmp_path: Path, debian_rosmaster, ros_home):
    """A minros node publishing String 'msg N' on /chatter at 50 Hz once someone listens."""
    require_reference()
    script = tmp_path / "talker.py"
    script.write_text(TALKER)
    proc = Proc([PYTHON, str(script), "/chatter", "string", "100000", "50", "0", "__name:=talker"],
                ros_env(debian_rosmaster, ros_home))
    try:
        wait_until(lambda: "/talker" in _tool(debian_rosmaster, ros_home, "rosnode", "list").stdout,
                   15, what="/talker registered")
        yield proc
    finally:
        proc.stop()


def test_rostopic_echo(talker, debian_rosmaster, ros_home):
    result = _tool(debian_rosmaster, ros_home, "rostopic", "echo", "-n", "2", "/chatter")
    assert result.returncode == 0, result.stderr
    assert re.fullmatch(r'data: "msg (\d+)"\n---\ndata: "msg (\d+)"\n---\n', result.stdout), result.stdout


def test_rostopic_hz(talker, debian_rosmaster, ros_home):
    proc = Proc(["/usr/bin/rostopic", "hz", "/chatter"], reference_env(ros_env(debian_rosmaster, ros_home)))
    try:
        out = proc.read_until("average rate:", 15)
        out += proc.read_until("average rate:", 5)
    finally:
        proc.stop()
    rates = [float(x) for x in re.findall(r"average rate: ([\d.]+)", out)]
    assert rates and all(40 < r < 60 for r in rates), out


def test_rostopic_info_and_type(talker, debian_rosmaster, ros_home):
    result = _tool(debian_rosmaster, ros_home, "rostopic", "type", "/chatter")
    assert result.stdout.strip() == "std_msgs/String"
    info = _tool(debian_rosmaster, ros_home, "rostopic", "info", "/chatter").stdout
    assert "Type: std_msgs/String" in info and "/talker (http://localhost:" in info


def test_rostopic_pub_to_minros_listener(tmp_path, debian_rosmaster, ros_home):
    require_reference()
    script = tmp_path / "listener.py"
    script.write_text(LISTENER)
    listener = Proc([PYTHON, str(script), "/typed", "string", "1"], ros_env(debian_rosmaster, ros_home))
    try:
        listener.read_until("subscribed", 20)
        result = _tool(debian_rosmaster, ros_home, "rostopic", "pub", "-1", "/typed",
                       "std_msgs/String", "data: typed by hand")
        assert result.returncode == 0, result.stderr
        out = listener.read_until("listener done 1", 10)
    finally:
        listener.stop()
    assert "got typed by hand from /rostopic" in out


def test_rosnode_info_ping_kill(talker, debian_rosmaster, ros_home):
    echo = Proc(["/usr/bin/rostopic", "echo", "/chatter"], reference_env(ros_env(debian_rosmaster, ros_home)))
    try:
        echo.read_until("data:", 15)
        info = _tool(debian_rosmaster, ros_home, "rosnode", "info", "/talker").stdout
        assert "Node [/talker]" in info
        assert " * /chatter [std_msgs/String]" in info and " * /rosout [rosgraph_msgs/Log]" in info
        assert f"Pid: {talker.pid}" in info
        # the connection block comes from parsing getBusInfo's info string
        assert re.search(r" \* topic: /chatter\n    \* to: /rostopic_\d+_\d+\n"
                         r"    \* direction: outbound \(\d+ - 127\.0\.0\.1:\d+\) \[\d+\]\n"
                         r"    \* transport: TCPROS", info), info
        ping = _tool(debian_rosmaster, ros_home, "rosnode", "ping", "-c", "2", "/talker").stdout
        assert len(re.findall(r"xmlrpc reply from http://localhost:\d+/\ttime=", ping)) == 2
        kill = _tool(debian_rosmaster, ros_home, "rosnode", "kill", "/talker")
        assert "killed" in kill.stdout
        talker.popen.wait(10)
        assert "shutdown request: user request" in talker.output()
        # unregistered in one multicall: the master no longer knows the node
        assert "/talker" not in _tool(debian_rosmaster, ros_home, "rosnode", "list").stdout
    finally:
        echo.stop()


def test_debian_master_restart_under_minros_pair(tmp_path, ros_home):
    """Kill Debian's rosmaster under a running minros pair and start a new one on the same
    port: the nodes register again by themselves, and a publisher restarted afterwards (new
    ports) reaches the subscriber through the new master."""
    import xmlrpc.client

    from support import free_port, wait_for_master

    require_reference()
    port = free_port()
    talker, listener = tmp_path / "talker.py", tmp_path / "listener.py"
    talker.write_text(TALKER)
    listener.write_text(LISTENER)

    def start_master() -> Proc:
        proc = Proc(["/usr/bin/rosmaster", "--core", "-p", str(port)], reference_env(ros_env(port, ros_home)))
        wait_for_master(port)
        return proc

    master = start_master()
    sub = Proc([PYTHON, str(listener), "/again", "string", "100000"], ros_env(port, ros_home))
    pub = Proc([PYTHON, str(talker), "/again", "string", "100000", "20", "0"], ros_env(port, ros_home))
    pub2 = None
    try:
        sub.read_until("got msg 3 from /talker", 20)
        master.stop()
        master = start_master()
        proxy = xmlrpc.client.ServerProxy(f"http://127.0.0.1:{port}/")

        def registered():
            pubs, subs, _ = proxy.getSystemState("/t")[2]
            return any(t == "/again" for t, _ in pubs) and any(t == "/again" for t, _ in subs)
        wait_until(registered, 10, what="both nodes registered with the new rosmaster")
        pub.stop()
        pub2 = Proc([PYTHON, str(talker), "/again", "string", "100000", "20", "0", "__name:=talker2"],
                    ros_env(port, ros_home))
        pub2.read_until("subscriber connected", 15)
        sub.read_until("from /talker2", 15)
    finally:
        for proc in (sub, pub, pub2, master):
            if proc is not None:
                proc.stop()
