"""roslaunch's data model and helper modules over minros's loader: XmlLoader fills a
ROSLaunchConfig with roslaunch's objects; node_args, arg_dump, param_dump, check_roslaunch."""

from __future__ import annotations

import io
from contextlib import redirect_stdout
from pathlib import Path

import pytest

import roslaunch.arg_dump
import roslaunch.config
import roslaunch.core
import roslaunch.depends
import roslaunch.node_args
import roslaunch.param_dump
import roslaunch.rlutil
import roslaunch.xmlloader

LAUNCH = """<launch>
  <arg name="rate" default="5" doc="how often"/>
  <arg name="who"/>
  <machine name="here" address="localhost"/>
  <param name="/global" value="1"/>
  <group ns="robot">
    <node pkg="demo_pkg" type="talker.py" name="talker" args="--rate $(arg rate)" output="screen" machine="here">
      <remap from="chatter" to="words"/>
      <param name="who" value="$(arg who)"/>
    </node>
    <test test-name="check" pkg="demo_pkg" type="talker.py" name="checker" time-limit="30"/>
  </group>
</launch>
"""


@pytest.fixture
def launch_file(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> Path:
    pkg = tmp_path / "demo_pkg"
    (pkg / "launch").mkdir(parents=True)
    (pkg / "package.xml").write_text("<package format='2'><name>demo_pkg</name><version>0.0.0</version>"
                                     "<description>d</description><maintainer email='a@b.org'>a</maintainer>"
                                     "<license>BSD</license></package>")
    script = pkg / "scripts" / "talker.py"
    script.parent.mkdir()
    script.write_text("#!/usr/bin/env python3\n")
    script.chmod(0o755)
    monkeypatch.setenv("ROS_PACKAGE_PATH", str(tmp_path))
    path = pkg / "launch" / "demo.launch"
    path.write_text(LAUNCH)
    return path


def test_xmlloader_fills_a_roslaunch_config(launch_file: Path):
    config = roslaunch.config.ROSLaunchConfig()
    roslaunch.xmlloader.XmlLoader().load(str(launch_file), config, argv=["x", "who:=bob"], verbose=False)
    (node,) = config.nodes
    assert isinstance(node, roslaunch.core.Node)
    assert (node.namespace, node.name, node.args, node.output, node.machine_name) == \
        ("/robot/", "talker", "--rate 5", "screen", "here")
    assert node.remap_args == [["chatter", "words"]]  # lists, as roslaunch's loader gives
    assert config.params["/robot/talker/who"] == roslaunch.core.Param("/robot/talker/who", "bob")
    assert config.params["/global"].value == 1
    assert config.machines["here"].address == "localhost"
    (test,) = config.tests
    assert (test.test_name, test.time_limit, test.xmltype()) == ("check", 30.0, "test")
    assert str(launch_file) in config.roslaunch_files
    assert '<node pkg="demo_pkg" type="talker.py"' in node.to_xml()


def test_bad_xml_is_roslaunchs_exception_and_text():
    with pytest.raises(roslaunch.xmlloader.XmlParseException) as info:
        roslaunch.xmlloader.XmlLoader().load_string("<foo />", roslaunch.config.ROSLaunchConfig())
    assert str(info.value) == "Invalid roslaunch XML syntax: no root <launch> tag"


def test_node_args_arg_dump_param_dump_and_check(launch_file: Path, monkeypatch: pytest.MonkeyPatch):
    monkeypatch.setattr("sys.argv", ["roslaunch", "who:=bob"])
    args = roslaunch.node_args.get_node_args("/robot/talker", [str(launch_file)])
    assert 'ROS_NAMESPACE="/robot"' in args
    assert args[-4:] == ["--rate", "5", "chatter:=words", "__name:=talker"]
    assert args[-5].endswith("talker.py")
    assert roslaunch.node_args.get_node_list(
        roslaunch.config.load_config_default([str(launch_file)], None, assign_machines=False)) == \
        ["/robot/talker", "/robot/checker"]
    assert roslaunch.arg_dump.get_args([str(launch_file)]) == {"rate": ("how often", "5"),
                                                                "who": (None, None)}
    out = io.StringIO()
    with redirect_stdout(out):
        assert roslaunch.param_dump.dump_params([str(launch_file)])
    assert "/global: 1" in out.getvalue() and "/robot/talker/who: bob" in out.getvalue()
    assert roslaunch.rlutil.check_roslaunch(str(launch_file)) is None  # who:=bob on the command line
    monkeypatch.setattr("sys.argv", ["roslaunch"])
    assert "requires the 'who' arg to be set" in roslaunch.rlutil.check_roslaunch(str(launch_file))
    assert roslaunch.rlutil.check_roslaunch(str(launch_file), ignore_unset_args=True) is None
    launch_file.write_text(LAUNCH.replace('pkg="demo_pkg" type="talker.py" name="talker"',
                                          'pkg="nowhere_pkg" type="x" name="talker"'))
    # as roslaunch: with ignore_unset_args, the walk for packages ends at the arg without a
    # value, so only a file whose args have values is checked for them
    assert roslaunch.rlutil.check_roslaunch(str(launch_file), ignore_unset_args=True) is None
    monkeypatch.setattr("sys.argv", ["roslaunch", "who:=bob"])
    problems = roslaunch.rlutil.check_roslaunch(str(launch_file))
    assert problems.splitlines() == [
        "Missing package dependencies: demo_pkg/package.xml: nowhere_pkg",
        "cannot find package [nowhere_pkg] for node [x]",
        "cannot find node [x] in package [nowhere_pkg]"]


def test_depends_walks_files_as_roslaunch_deps(launch_file: Path, monkeypatch: pytest.MonkeyPatch):
    monkeypatch.setattr("sys.argv", ["roslaunch-deps"])
    inc = launch_file.parent / "inc.launch"
    inc.write_text('<launch><arg name="x"/><node pkg="$(arg x)" type="t" name="n"/></launch>')
    launch_file.write_text(f'''<launch>
  <include file="{inc}"><arg name="x" value="rospy"/></include>
  <node pkg="demo_pkg" type="talker.py" name="a" if="true"/>
  <node pkg="std_msgs" type="no" name="b" unless="true"/>
</launch>''')
    base, file_deps, missing = roslaunch.depends.roslaunch_deps([str(launch_file)])
    assert base == "demo_pkg"
    assert file_deps == {
        str(launch_file): roslaunch.depends.RoslaunchDeps(nodes=[("demo_pkg", "talker.py")],
                                                          includes=[str(inc)], pkgs=["demo_pkg"]),
        str(inc): roslaunch.depends.RoslaunchDeps(nodes=[("rospy", "t")], pkgs=["rospy"])}
    assert missing == {"demo_pkg": {"rospy"}}
    out = io.StringIO()
    with redirect_stdout(out):
        roslaunch.depends.roslaunch_deps_main(["roslaunch-deps", str(launch_file), "--warn"])
    assert out.getvalue().splitlines()[-3:] == ["Missing declarations:", "demo_pkg/manifest.xml:",
                                                '  <depend package="rospy" />']


def test_core_checks_and_texts():
    from roslaunch.core import Node, Test, add_printlog_handler, clear_printlog_handlers, printlog

    for kwargs, text in [({"cwd": "foo"}, "cwd must be one of 'ROS_HOME', 'node'"),
                         ({"output": "x"}, "output must be one of 'log', 'screen'"),
                         ({"name": "a/b"}, "node name cannot contain a namespace"),
                         ({"respawn": True, "required": True},
                          "respawn and required cannot both be set to true")]:
        with pytest.raises(ValueError, match=text):
            Node("pkg", "type", **kwargs)
    assert Node("pkg", "type", cwd="ros_home", namespace="//a//b").cwd == "ROS_HOME"
    t = Test("t", "pkg", "type", retry=2, time_limit=5)
    assert t.output == "log" and t.name is None
    assert t.xmlattrs()[-3:] == [("test-name", "t"), ("retry", "2"), ("time-limit", 5.0)]
    with pytest.raises(ValueError, match="'time-limit' must be a number"):
        Test("t", "pkg", "type", time_limit="5")

    def boom(msg):
        raise RuntimeError(msg)

    add_printlog_handler(boom)  # a failing handler does not stop printlog
    try:
        out = io.StringIO()
        with redirect_stdout(out):
            printlog("hello")
        assert out.getvalue() == "hello\n"
    finally:
        clear_printlog_handlers()


def test_rosparam_errors_are_load_exceptions():
    import roslaunch.loader

    with pytest.raises(roslaunch.loader.LoadException, match="command must be 'load'"):
        roslaunch.xmlloader.XmlLoader().load_string('<launch><rosparam command="bad"/></launch>',
                                                    roslaunch.config.ROSLaunchConfig())
