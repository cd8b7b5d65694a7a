"""roslaunch as a process: parameters on the master, remaps and namespaces, required and
respawning nodes, Ctrl-C cleanup, bad input."""

from __future__ import annotations

import os
import re
import signal
import subprocess
import sys
import time
import xmlrpc.client
from pathlib import Path

import pytest

from support import Proc, free_port, ros_env, wait_for_master, wait_until

BIN = Path(sys.executable).parent

# Prints what roslaunch gave it, then waits (or exits / ignores SIGINT as asked by argv).
PROBE = """#!/usr/bin/env python
import os, signal, sys, time
args = sys.argv[1:]
if "--ignore-sigint" in args:  # before the PROBE line: the test signals right after seeing it
    signal.signal(signal.SIGINT, signal.SIG_IGN)
# one write() per line: the tests run nodes with PYTHONUNBUFFERED=1, where print() writes
# piece by piece and two nodes sharing the screen could interleave inside a line
os.write(1, ("PROBE %d %s %s %s %s\\n" % (os.getpid(), os.environ.get("ROS_NAMESPACE", "-"),
             os.environ.get("PROBE_ENV", "-"), os.getcwd(), " ".join(args))).encode())
if "--pidfile" in args:
    with open(args[args.index("--pidfile") + 1], "a") as f:
        f.write("%d\\n" % os.getpid())
if "--exit-after" in args:
    time.sleep(float(args[args.index("--exit-after") + 1]))
    sys.exit(int(args[args.index("--code") + 1]) if "--code" in args else 0)
try:
    while True:
        time.sleep(1)
except KeyboardInterrupt:
    pass
"""

# A rospy node that reports how it resolves names and its private parameter.
NAMES_NODE = """#!/usr/bin/env python
import sys
import rospy
rospy.init_node("names_node")
sys.stdout.write("NAMES %s %s %s %s\\n" % (rospy.get_name(), rospy.resolve_name("chatter"),
                 rospy.resolve_name("other"), rospy.get_param("~priv")))  # one write() (see PROBE)
sys.stdout.flush()
rospy.spin()
"""


@pytest.fixture
def pkg(tmp_path: Path) -> Path:
    root = tmp_path / "src" / "launch_probe"
    (root / "scripts").mkdir(parents=True)
    (root / "package.xml").write_text(
        '<?xml version="1.0"?><package format="2"><name>launch_probe</name><version>0.0.0</version>'
        "<description>d</description><maintainer email='a@b.c'>a</maintainer><license>BSD</license>"
        "</package>\n")
    for name, text in (("probe.py", PROBE), ("names_node.py", NAMES_NODE)):
        (root / "scripts" / name).write_text(text)
        (root / "scripts" / name).chmod(0o755)
    (root / "data.bin").write_bytes(b"\x00\xffbin")
    return root


def _launch_args(tmp_path: Path, pkg: Path, xml: str, *extra: str, port=None, port_option=True):
    """roslaunch's argv and environment for ``xml``: ROS_MASTER_URI names ``port``, which is
    also passed as ``-p`` unless ``port_option`` is False."""
    port = port or free_port()
    launch_file = tmp_path / "test.launch"
    launch_file.write_text(xml)
    env = ros_env(port, tmp_path / "home", {"ROS_PACKAGE_PATH": str(pkg.parent)})
    argv = [str(BIN / "roslaunch"), str(launch_file), *(["-p", str(port)] if port_option else []), *extra]
    return argv, env, port


def _launch(tmp_path: Path, pkg: Path, xml: str, *extra: str, port=None):
    argv, env, port = _launch_args(tmp_path, pkg, xml, *extra, port=port)
    return Proc(argv, env), port


def _pids(output: str):
    return [int(p) for p in re.findall(r"started with pid \[(\d+)\]", output)]


def _gone(pid: int) -> bool:
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return True
    # a zombie is gone for our purpose only once reaped; roslaunch reaps its children
    try:
        with open(f"/proc/{pid}/stat") as f:
            return f.read().split()[2] == "Z"
    except OSError:
        return True


def test_parameters_of_every_type_reach_the_master(tmp_path, pkg):
    yaml_file = tmp_path / "conf.yaml"
    yaml_file.write_text("gains: {p: 1.5, i: 0}\nnames: [a, b]\nangle: deg(90)\n")
    xml = f"""<launch>
      <arg name="speed" default="7"/>
      <param name="int_p" value="42"/>
      <param name="float_p" value="0.25"/>
      <param name="bool_p" value="true"/>
      <param name="str_p" value="hello"/>
      <param name="forced_str" type="str" value="12"/>
      <param name="forced_double" type="double" value="3"/>
      <param name="yaml_p" type="yaml" value="[1, two, 3.0]"/>
      <param name="arg_p" value="$(arg speed)"/>
      <param name="text_p" textfile="$(find launch_probe)/package.xml"/>
      <param name="bin_p" binfile="$(find launch_probe)/data.bin"/>
      <param name="cmd_p" command="echo from-command"/>
      <rosparam file="{yaml_file}" command="load" ns="conf"/>
      <group ns="robot">
        <rosparam>inline: {{deep: true}}</rosparam>
        <node pkg="launch_probe" type="probe.py" name="probe" output="screen">
          <param name="private_p" value="9"/>
        </node>
      </group>
    </launch>"""
    proc, port = _launch(tmp_path, pkg, xml, "speed:=11")
    try:
        head = proc.read_until("PROBE", timeout=20)
        master = xmlrpc.client.ServerProxy(f"http://127.0.0.1:{port}/")

        def get(key):
            code, msg, value = master.getParam("/test", key)
            assert code == 1, (key, msg)
            return value

        expected = {
            "/int_p": 42, "/float_p": 0.25, "/bool_p": True, "/str_p": "hello", "/forced_str": "12",
            "/forced_double": 3.0, "/yaml_p": [1, "two", 3.0], "/arg_p": 11, "/cmd_p": "from-command\n",
            "/conf/gains/p": 1.5, "/conf/gains/i": 0, "/conf/names": ["a", "b"],
            "/robot/inline/deep": True, "/robot/probe/private_p": 9,
        }
        for key, value in expected.items():
            got = get(key)
            assert got == value and type(got) is type(value), key
        assert get("/conf/angle") == pytest.approx(1.5707963267948966)
        assert "<name>launch_probe</name>" in get("/text_p")
        binary = get("/bin_p")
        assert isinstance(binary, xmlrpc.client.Binary) and binary.data == b"\x00\xffbin"
        run_id = get("/run_id")
        assert re.fullmatch(r"[0-9a-f-]{36}", run_id)
    finally:
        out = head + proc.stop()
    assert "PARAMETERS\n * /arg_p: 11\n" in out
    assert "auto-starting new master" in out and f"ROS_MASTER_URI=http://localhost:{port}/" in out


def test_remaps_namespaces_env_and_args_reach_the_node(tmp_path, pkg):
    xml = """<launch>
      <remap from="chatter" to="global_chat"/>
      <group ns="ns1">
        <env name="PROBE_ENV" value="from-group"/>
        <node pkg="launch_probe" type="probe.py" name="p1" args="--flag 'two words'" output="screen"
              cwd="node">
          <remap from="other" to="/elsewhere"/>
        </node>
        <node pkg="launch_probe" type="names_node.py" name="names" output="screen">
          <remap from="other" to="/elsewhere"/>
          <param name="priv" value="secret"/>
        </node>
      </group>
    </launch>"""
    proc, _port = _launch(tmp_path, pkg, xml)
    try:
        probe = proc.read_until("PROBE", timeout=20)
        line = next(ln for ln in probe.splitlines() if ln.startswith("PROBE"))
        _pid, ns, env_value, cwd, args = line.split(" ", 5)[1:]
        assert ns == "/ns1" and env_value == "from-group"  # no trailing slash, as roslaunch
        assert cwd == str(pkg / "scripts")
        assert args.startswith("--flag two words chatter:=global_chat other:=/elsewhere __name:=p1 __log:=")
        names = proc.read_until("NAMES", timeout=20)
        line = next(ln for ln in names.splitlines() if ln.startswith("NAMES"))
        assert line.split() == ["NAMES", "/ns1/names", "/ns1/global_chat", "/elsewhere", "secret"]
    finally:
        proc.stop()


def test_required_node_exit_stops_the_launch(tmp_path, pkg):
    xml = """<launch>
      <node pkg="launch_probe" type="probe.py" name="stays"/>
      <node pkg="launch_probe" type="probe.py" name="boss" required="true" args="--exit-after 0.5 --code 3"/>
    </launch>"""
    proc, _port = _launch(tmp_path, pkg, xml)
    try:
        proc.popen.wait(timeout=30)
    finally:
        out = proc.stop()
    assert "REQUIRED process [boss-2] has died!" in out
    assert "process has died [pid" in out and "exit code 3" in out and "Initiating shutdown!" in out
    assert "[stays-1] killing on exit" in out
    assert all(_gone(pid) for pid in _pids(out))
    # output="log" (the default): the node's stdout is in <log dir>/<run_id>/<name>-stdout.log
    log_root = tmp_path / "home" / "log"
    logs = [p for p in log_root.glob("*/boss-2-stdout.log") if p.parent.name != "latest"]
    assert len(logs) == 1 and logs[0].read_text().startswith("PROBE ")
    # as roslaunch: <log dir>/latest links to this run's directory
    assert (log_root / "latest").is_symlink() and (log_root / "latest").resolve() == logs[0].parent
    assert f"log file: {logs[0].parent / 'boss-2'}*.log" in out


def test_respawning_node_comes_back(tmp_path, pkg):
    pidfile = tmp_path / "pids.txt"
    xml = f"""<launch>
      <node pkg="launch_probe" type="probe.py" name="phoenix" respawn="true" respawn_delay="0.2"
            args="--pidfile {pidfile} --exit-after 0.3"/>
    </launch>"""
    proc, _port = _launch(tmp_path, pkg, xml)
    try:
        wait_until(lambda: pidfile.exists() and len(set(pidfile.read_text().split())) >= 3, timeout=30,
                   what="three incarnations of the respawning node")
        assert proc.alive()
    finally:
        out = proc.stop()
    assert out.count("[phoenix-1] restarting process") >= 2
    assert "[phoenix-1] process has finished cleanly" in out
    assert all(_gone(pid) for pid in _pids(out))


def test_ctrl_c_leaves_no_process_behind(tmp_path, pkg):
    xml = """<launch>
      <node pkg="launch_probe" type="probe.py" name="a"/>
      <group ns="g"><node pkg="launch_probe" type="probe.py" name="b" output="screen"/></group>
      <node pkg="launch_probe" type="probe.py" name="stubborn" args="--ignore-sigint" output="screen"/>
    </launch>"""
    proc, port = _launch(tmp_path, pkg, xml, "--sigint-timeout", "1", "--sigterm-timeout", "1")
    try:
        wait_for_master(port)
        text = proc.read_until("process[stubborn-3]: started", timeout=20)
        text += proc.read_until("--ignore-sigint", timeout=20)  # its handler is installed
        pids = _pids(text)  # the master (and whatever it started) and the three nodes
        for name in ("a-1", "g/b-2", "stubborn-3", "master"):
            assert f"process[{name}]: started with pid" in text
        os.killpg(proc.pid, signal.SIGINT)
        proc.popen.wait(timeout=30)
    finally:
        out = proc.stop()
    for name in ("stubborn-3", "g/b-2", "a-1", "master"):
        assert f"[{name}] killing on exit" in out
    assert out.index("[stubborn-3] killing") < out.index("[a-1] killing") < out.index("[master] killing")
    assert "[stubborn-3] escalating to SIGTERM" in out
    assert out.rstrip().endswith("done")
    deadline = time.monotonic() + 5
    while not all(_gone(pid) for pid in pids) and time.monotonic() < deadline:
        time.sleep(0.05)
    assert all(_gone(pid) for pid in pids)


def test_existing_master_is_used_and_left_running(tmp_path, pkg, minros_master):
    xml = '<launch><param name="x" value="1"/><node pkg="launch_probe" type="probe.py" name="n"/></launch>'
    proc, port = _launch(tmp_path, pkg, xml, port=minros_master)
    try:
        proc.read_until("process[n-1]: started", timeout=20)
    finally:
        out = proc.stop()
    assert "auto-starting new master" not in out and "[master] killing on exit" not in out
    wait_for_master(port, timeout=2)  # still up


def test_master_remap_argument_beats_the_environment(tmp_path, pkg, minros_master):
    # as real roslaunch (rosgraph.get_master_uri): __master:= wins over ROS_MASTER_URI, and the
    # nodes it starts are pointed at that master too
    xml = """<launch><param name="x" value="1"/>
      <node pkg="launch_probe" type="names_node.py" name="names" output="screen">
        <param name="priv" value="p"/>
      </node></launch>"""
    argv, env, _port = _launch_args(tmp_path, pkg, xml, f"__master:=http://localhost:{minros_master}",
                                    port_option=False)  # ROS_MASTER_URI names a port nobody serves
    proc = Proc(argv, env)
    head = ""
    try:
        head = proc.read_until("NAMES /names", timeout=30)
        master = xmlrpc.client.ServerProxy(f"http://localhost:{minros_master}")
        assert master.getParam("/t", "/x")[2] == 1
        assert master.lookupNode("/t", "/names")[0] == 1
    finally:
        out = head + proc.stop()
    assert "auto-starting new master" not in out
    assert f"ROS_MASTER_URI=http://localhost:{minros_master}/" in out


def test_master_remap_argument_without_a_value_is_an_error(tmp_path, pkg):
    argv, env, _port = _launch_args(tmp_path, pkg, '<launch><param name="x" value="1"/></launch>',
                                    "__master:=", port_option=False)
    done = subprocess.run(argv, env=env, capture_output=True, text=True, timeout=30)
    assert done.returncode == 1
    assert done.stderr.strip() == ("roslaunch: error: __master remapping argument '__master:=' "
                                   "improperly specified")
    assert "Traceback" not in done.stderr + done.stdout


def test_bad_nodes_are_reported_and_the_rest_runs(tmp_path, pkg):
    (pkg / "scripts" / "noexec.py").write_text(PROBE)
    xml = """<launch>
      <node pkg="no_such_pkg" type="x" name="ghost"/>
      <node pkg="launch_probe" type="noexec.py" name="noexec"/>
      <node pkg="launch_probe" type="probe.py" name="fine" output="screen"/>
      <unknown_tag/>
    </launch>"""
    proc, _port = _launch(tmp_path, pkg, xml)
    try:
        head = proc.read_until("PROBE", timeout=20)
    finally:
        out = head + proc.stop()
    assert "ERROR: cannot launch node of type [no_such_pkg/x]: no_such_pkg" in out
    assert "ERROR: cannot launch node of type [launch_probe/noexec.py]: Cannot locate node of type [noexec.py]" in out
    assert re.search(r"WARNING: \[.*test.launch:5\] unrecognized tag unknown_tag", out)


@pytest.mark.parametrize("xml,needle", [
    ("<launch><node pkg='p' type='t'/></launch>", "test.launch:1: <node> tag is missing required attribute 'name'"),
    ("<launch>\n<param name='x' value='$(arg nope)'/>\n</launch>", "test.launch: requires the 'nope' arg to be set"),
    ("<launch><param name='x' value='1'></launch>", "test.launch:1: Invalid roslaunch XML syntax: mismatched tag"),
])
def test_bad_launch_files_fail_with_one_line(tmp_path, pkg, xml, needle):
    proc, _port = _launch(tmp_path, pkg, xml)
    code = proc.popen.wait(timeout=30)
    out = proc.output()
    assert code == 1
    lines = out.strip().splitlines()
    assert len(lines) == 1 and needle in lines[0] and lines[0].startswith("roslaunch: error: ")


def test_roslaunch_pkg_file_form_and_unknown(tmp_path, pkg):
    (pkg / "launch").mkdir()
    (pkg / "launch" / "probe.launch").write_text(
        '<launch><node pkg="launch_probe" type="probe.py" name="n"/></launch>')
    env = ros_env(None, tmp_path / "home", {"ROS_PACKAGE_PATH": str(pkg.parent)})
    nodes = Proc([str(BIN / "roslaunch"), "--nodes", "launch_probe", "probe.launch"], env)
    assert nodes.popen.wait(timeout=30) == 0 and nodes.output().strip() == "/n"
    bad = Proc([str(BIN / "roslaunch"), "launch_probe", "nope.launch"], env)
    assert bad.popen.wait(timeout=30) == 1
    assert bad.output().strip() == ("roslaunch: error: [nope.launch] is neither a launch file in package "
                                    "[launch_probe] nor is [launch_probe] a launch file name")


def test_killed_roslaunch_takes_its_nodes_along(tmp_path, pkg):
    xml = '<launch><node pkg="launch_probe" type="probe.py" name="orphan" output="screen"/></launch>'
    proc, _port = _launch(tmp_path, pkg, xml)
    try:
        text = proc.read_until("PROBE", timeout=20)
        pids = _pids(text)
        assert len(pids) >= 2  # master and node
        os.kill(proc.pid, signal.SIGKILL)  # roslaunch alone, no chance to clean up
        wait_until(lambda: all(_gone(pid) for pid in pids), timeout=10, what="children gone")
    finally:
        proc.stop()


def test_screen_flag_and_launch_prefix(tmp_path, pkg):
    xml = """<launch>
      <node pkg="launch_probe" type="probe.py" name="quiet" launch-prefix="env PROBE_ENV=prefixed"/>
    </launch>"""
    proc, _port = _launch(tmp_path, pkg, xml, "--screen")
    try:
        text = proc.read_until("PROBE", timeout=20)  # output="log" node, shown because of --screen
    finally:
        proc.stop()
    line = next(ln for ln in text.splitlines() if ln.startswith("PROBE"))
    assert line.split()[3] == "prefixed"


# A keyboard teleop's first moves: the terminal's attributes, raw mode, one key.
KEYS_NODE = """#!/usr/bin/env python
import os, termios, tty
old = termios.tcgetattr(0)  # termios.error (25, 'Inappropriate ioctl') unless stdin is a tty
tty.setraw(0)
try:
    os.write(1, b"KEYS ready\\r\\n")
    key = os.read(0, 1)
finally:
    termios.tcsetattr(0, termios.TCSADRAIN, old)
os.write(1, b"KEY %s\\n" % key)
"""


def test_nodes_read_the_terminal_roslaunch_runs_in(tmp_path, pkg):
    """As ROS's roslaunch, nodes inherit its stdin: a teleop reads keys from the terminal."""
    import fcntl
    import pty
    import select
    import termios

    (pkg / "scripts" / "keys.py").write_text(KEYS_NODE)
    (pkg / "scripts" / "keys.py").chmod(0o755)
    xml = """<launch>
      <node pkg="launch_probe" type="keys.py" name="keys" output="screen" required="true"/>
    </launch>"""
    argv, env, _port = _launch_args(tmp_path, pkg, xml)
    master_fd, slave_fd = pty.openpty()

    def controlling_terminal() -> None:  # roslaunch as started from a shell in that terminal
        fcntl.ioctl(0, termios.TIOCSCTTY, 0)

    proc = subprocess.Popen(argv, env=env, stdin=slave_fd, stdout=slave_fd, stderr=slave_fd,
                            start_new_session=True, preexec_fn=controlling_terminal)
    os.close(slave_fd)
    seen = b""

    def read_until(needle: bytes, timeout: float) -> None:
        nonlocal seen
        deadline = time.monotonic() + timeout
        while needle not in seen:
            remaining = deadline - time.monotonic()
            assert remaining > 0, f"{needle!r} not seen; terminal showed:\n{seen.decode(errors='replace')}"
            if select.select([master_fd], [], [], remaining)[0]:
                try:
                    seen += os.read(master_fd, 4096)
                except OSError:  # EIO: every process let go of the terminal
                    break
        assert needle in seen, seen.decode(errors="replace")

    try:
        read_until(b"KEYS ready", 30)
        os.write(master_fd, b"k")
        read_until(b"KEY k", 10)
        assert proc.wait(30) == 0  # the required node finished: roslaunch ends
    finally:
        if proc.poll() is None:
            os.killpg(proc.pid, signal.SIGINT)
            try:
                proc.wait(20)
            except subprocess.TimeoutExpired:
                os.killpg(proc.pid, signal.SIGKILL)
                proc.wait(5)
        os.close(master_fd)
    assert b"Inappropriate ioctl" not in seen
