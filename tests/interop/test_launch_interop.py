"""roslaunch against Debian's roslaunch (the oracle) and against Debian's rosmaster."""

from __future__ import annotations

import os
import re
import subprocess
import sys
import xmlrpc.client
from pathlib import Path

import pytest
import yaml

from support import Proc, reference_env, require_reference, ros_env

pytestmark = pytest.mark.interop

BIN = Path(sys.executable).parent

INNER = """<launch>
  <arg name="who"/>
  <arg name="level" default="3"/>
  <param name="who" value="$(arg who)"/>
  <param name="level" value="$(arg level)"/>
  <param name="~inherited" value="in-include"/>
  <node pkg="lprobe" type="probe.py" name="inner_node">
    <param name="own" value="$(eval arg('level') * 2)"/>
  </node>
</launch>
"""

TOP = """<launch>
  <arg name="flag" default="true"/>
  <arg name="speed" default="1.5"/>
  <arg name="name" default="robot"/>
  <param name="i" value="7"/>
  <param name="neg" value="-7"/>
  <param name="f" value="2.50"/>
  <param name="exp" value="1e3"/>
  <param name="under" value="1_000"/>
  <param name="b" value="False"/>
  <param name="s" value=" padded "/>
  <param name="t_str" type="str" value="42"/>
  <param name="t_int" type="int" value="42"/>
  <param name="t_double" type="double" value="42"/>
  <param name="t_bool" type="bool" value="1"/>
  <param name="t_yaml" type="yaml" value="{a: [1, 2.5, x], b: {c: true}}"/>
  <param name="text" textfile="$(find lprobe)/note.txt"/>
  <param name="found" value="$(find lprobe)/x"/>
  <param name="env" value="$(env LAUNCH_TEST_VAR)"/>
  <param name="optenv" value="$(optenv LAUNCH_UNSET_VAR fallback value)"/>
  <param name="dir" value="$(dirname)"/>
  <param name="eval" value="$(eval speed * 2 if flag else 0)"/>
  <param name="evalstr" value="$(eval name + '_' + str(int(speed)))"/>
  <param name="when_flag" value="yes" if="$(arg flag)"/>
  <param name="unless_flag" value="no" unless="$(arg flag)"/>
  <rosparam file="$(dirname)/conf.yaml" command="load" ns="conf"/>
  <rosparam param="list_param">[1, 2, three]</rosparam>
  <rosparam subst_value="true">subst: $(arg name)</rosparam>
  <group ns="$(arg name)">
    <param name="~group_private" value="gp"/>
    <param name="grouped" value="1"/>
    <rosparam ns="nested">{deep: {deeper: 2}}</rosparam>
    <node pkg="lprobe" type="probe.py" name="n1" args="--x 1">
      <param name="p" value="3"/>
      <rosparam>{r: [a, b]}</rosparam>
      <remap from="a" to="b"/>
    </node>
    <include file="$(dirname)/inner.launch" ns="inc">
      <arg name="who" value="$(arg name)"/>
    </include>
  </group>
  <include file="$(dirname)/inner.launch" pass_all_args="true">
    <arg name="who" value="all"/>
  </include>
  <node pkg="lprobe" type="probe.py" name="top_node" ns="ns_attr"/>
</launch>
"""


@pytest.fixture
def launch_dir(tmp_path: Path) -> Path:
    pkg = tmp_path / "src" / "lprobe"
    (pkg / "scripts").mkdir(parents=True)
    (pkg / "package.xml").write_text(
        '<?xml version="1.0"?><package format="2"><name>lprobe</name><version>0.0.0</version>'
        "<description>d</description><maintainer email='a@b.c'>a</maintainer><license>BSD</license>"
        "</package>\n")
    (pkg / "note.txt").write_text("line one\nline two\n")
    probe = pkg / "scripts" / "probe.py"
    probe.write_text("#!/usr/bin/env python\nimport time\ntime.sleep(60)\n")
    probe.chmod(0o755)
    launch = tmp_path / "launch"
    launch.mkdir()
    (launch / "top.launch").write_text(TOP)
    (launch / "inner.launch").write_text(INNER)
    (launch / "conf.yaml").write_text("gain: 0.5\nangles: {a: deg(180), b: rad(pi/2), c: !degrees 90}\n"
                                      "names: [x, y]\nempty: {}\n")
    return tmp_path


def _env(tmp_path: Path, port=None):
    env = ros_env(port, tmp_path / "home", {"ROS_PACKAGE_PATH": str(tmp_path / "src"),
                                            "LAUNCH_TEST_VAR": "from env"})
    env.pop("LAUNCH_UNSET_VAR", None)
    return env


def _run(argv, env, cwd):
    result = subprocess.run(argv, env=env, cwd=cwd, capture_output=True, text=True, timeout=60)
    assert result.returncode == 0, result.stdout + result.stderr
    return result.stdout


def _both(launch_dir: Path, *args: str):
    env = _env(launch_dir)
    cwd = launch_dir / "launch"
    ours = _run([str(BIN / "roslaunch"), *args], env, cwd)
    theirs = _run(["/usr/bin/roslaunch", *args], reference_env(env), cwd)
    return ours, theirs


def test_dump_params_matches_debian_roslaunch(launch_dir):
    require_reference()
    for argv in ((), ("flag:=false", "name:=bot", "speed:=4")):
        ours, theirs = _both(launch_dir, "--dump-params", "top.launch", *argv)
        mine, reference = yaml.safe_load(ours), yaml.safe_load(theirs)
        assert set(mine) == set(reference), set(mine) ^ set(reference)
        for key, value in reference.items():
            assert mine[key] == value and type(mine[key]) is type(value), (key, mine[key], value)


def test_nodes_files_and_args_match_debian_roslaunch(launch_dir):
    require_reference()
    ours, theirs = _both(launch_dir, "--nodes", "top.launch")
    assert ours.split() == theirs.split()
    ours, theirs = _both(launch_dir, "--files", "top.launch")
    assert sorted(ours.split()) == sorted(theirs.split())  # roslaunch prints them in set order
    for node in ("/robot/n1", "inner_node"):  # Debian roslaunch takes ~1 s per call
        ours, theirs = _both(launch_dir, "--args", node, "top.launch")
        # minros names its interpreter (the venv's python or python3, whichever the console
        # script's shebang names) in front of Python scripts; otherwise identical
        interpreter = re.compile(re.escape(str(Path(sys.executable).parent)) + r"/python[0-9.]* ")
        assert interpreter.sub("", ours).split() == theirs.split()


def test_params_land_in_debian_rosmaster_with_their_types(launch_dir, debian_rosmaster):
    env = _env(launch_dir, debian_rosmaster)
    proc = Proc([str(BIN / "roslaunch"), "top.launch"], env, cwd=launch_dir / "launch")
    try:
        proc.read_until("process[ns_attr/top_node-4]: started", timeout=30)
        master = xmlrpc.client.ServerProxy(f"http://127.0.0.1:{debian_rosmaster}/")
        expected = {"/i": 7, "/f": 2.5, "/b": False, "/s": "padded", "/t_str": "42", "/t_double": 42.0,
                    "/t_yaml": {"a": [1, 2.5, "x"], "b": {"c": True}}, "/robot/n1/r": ["a", "b"],
                    "/robot/inc/who": "robot", "/conf/names": ["x", "y"], "/robot/n1/group_private": "gp"}
        for key, value in expected.items():
            code, msg, got = master.getParam("/test", key)
            assert code == 1 and got == value and type(got) is type(value), (key, msg, got)
        code, _msg, names = master.getParamNames("/test")
        assert "/run_id" in names
    finally:
        out = proc.stop()
    assert "auto-starting new master" not in out
    assert os.path.isdir(launch_dir / "home" / "log")


def _summary_block(output: str) -> str:
    """The SUMMARY ... NODES block of roslaunch's output, without colour codes and without
    /rosdistro and /rosversion (their values name the distribution)."""
    import re

    text = re.sub(r"\x1b\[[0-9;]*m|\x1b\]2;[^\x07]*\x07", "", output)
    start = text.index("SUMMARY")
    end = text.index("\n\n", text.index("NODES", start) + len("NODES\n") + 1)
    lines = text[start:end].splitlines()
    return "\n".join(ln for ln in lines if not ln.startswith((" * /rosdistro", " * /rosversion")))


def test_summary_matches_debian_roslaunch(launch_dir, debian_rosmaster):
    env = _env(launch_dir, debian_rosmaster)
    cwd = launch_dir / "launch"
    blocks = []
    for argv, proc_env in (([str(BIN / "roslaunch")], env), (["/usr/bin/roslaunch"], reference_env(env))):
        proc = Proc(argv + ["top.launch", "name:=bot"], proc_env, cwd=cwd)
        try:
            text = proc.read_until("ROS_MASTER_URI=", timeout=30)
        finally:
            proc.stop()
        blocks.append(_summary_block(text))
    ours, theirs = blocks
    assert ours == theirs
    assert " * /t_yaml: {'a': [1, 2.5, 'x..." in ours  # long values cut to 20 characters


def test_debians_roscore_starts_with_minros_tools_first_on_path(tmp_path):
    """Debian's roscore.xml runs `rosversion roslaunch` and `rosversion -d`: with minros's venv
    first on PATH (as after `source devel/setup.bash`) they are minros's, and roscore starts."""
    from support import free_port, wait_for_master, wait_until

    require_reference()
    port = free_port()
    env = reference_env(ros_env(port, tmp_path / "home"))
    env["PATH"] = f"{BIN}:{env['PATH']}"
    assert subprocess.run(["which", "rosversion"], env=env, capture_output=True, text=True,
                          timeout=10).stdout.strip() == str(BIN / "rosversion")
    core = Proc(["/usr/bin/roscore", "-p", str(port)], env)
    try:
        wait_for_master(port, timeout=30)
        master = xmlrpc.client.ServerProxy(f"http://127.0.0.1:{port}/")
        wait_until(lambda: master.getParam("/t", "/rosdistro")[0] == 1, 30, what="/rosdistro set")
        assert master.getParam("/t", "/rosversion")[2] == "1.15.15\n"
        assert master.getParam("/t", "/rosdistro")[2] == "noetic\n"
        wait_until(lambda: master.lookupNode("/t", "/rosout")[0] == 1, 30, what="rosout up")
    finally:
        text = core.stop()
    assert "RLException" not in text and "Invalid <param> tag" not in text, text


def test_provided_packages_carry_debians_versions():
    """Every package minros provides that Debian installs has Debian's version."""
    from minros import packages

    require_reference()
    compared = 0
    for name, folder in sorted(packages.list_packages(refresh=True).items()):
        debian = Path("/usr/share") / name / "package.xml"
        if packages.is_builtin(folder) and debian.is_file():
            assert packages.manifest_version(folder) == packages.manifest_version(debian.parent), name
            compared += 1
    assert compared >= 30
