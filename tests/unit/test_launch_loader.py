"""roslaunch XML loader: scoping, parameters, args, includes, bad input (no processes)."""

from __future__ import annotations

import math
import xmlrpc.client
from pathlib import Path

import pytest

from minros.launch.config import LaunchError
from minros.launch.loader import load_launch, load_launch_string

HERE = Path(__file__).resolve().parent / "launch_files"


def load(text: str, argv=(), **kw):
    kw.setdefault("env", {"HOME": "/home/u", "PATH": "/usr/bin:/bin"})
    return load_launch_string(text, argv, **kw)


def write(tmp_path: Path, name: str, text: str) -> str:
    path = tmp_path / name
    path.write_text(text)
    return str(path)


def test_tutorial_launch_files_parse():
    mimic = load_launch(str(HERE / "turtlemimic.launch"))
    assert [(n.resolved_name, n.package, n.type) for n in mimic.nodes] == [
        ("/turtlesim1/sim", "turtlesim", "turtlesim_node"),
        ("/turtlesim2/sim", "turtlesim", "turtlesim_node"),
        ("/mimic", "turtlesim", "mimic"),
    ]
    assert mimic.nodes[2].remap_args == [("input", "turtlesim1/turtle1"), ("output", "turtlesim2/turtle1")]
    assert not mimic.warnings
    multi = load_launch(str(HERE / "multisim.launch"))
    assert [n.resolved_name for n in multi.nodes] == ["/turtlesim1/turtlesim", "/turtlesim2/turtlesim"]


@pytest.mark.slow
def test_param_types_and_sources(tmp_path: Path):
    text_file = write(tmp_path, "t.txt", "some text\n")
    bin_file = tmp_path / "b.bin"
    bin_file.write_bytes(b"\x00\x01\xff")
    cfg = load(f"""<launch>
      <param name="i" value=" 42 "/>
      <param name="f" value="1.5"/>
      <param name="b" value="True"/>
      <param name="s" value="hello"/>
      <param name="forced_str" value="7" type="str"/>
      <param name="forced_double" value="7" type="double"/>
      <param name="forced_bool" value="1" type="bool"/>
      <param name="y" type="yaml" value="{{a: [1, 2], b: x}}"/>
      <param name="text" textfile="{text_file}"/>
      <param name="bin" binfile="{bin_file}"/>
      <param name="cmd" command="echo 12"/>
    </launch>""")
    p = cfg.params
    assert (p["/i"], p["/f"], p["/b"], p["/s"]) == (42, 1.5, True, "hello")
    assert p["/forced_str"] == "7" and p["/forced_double"] == 7.0 and p["/forced_bool"] is True
    assert p["/y"] == {"a": [1, 2], "b": "x"}
    assert p["/text"] == "some text\n"
    assert isinstance(p["/bin"], xmlrpc.client.Binary) and p["/bin"].data == b"\x00\x01\xff"
    assert p["/cmd"] == 12


def test_namespaces_private_params_and_remaps():
    cfg = load("""<launch>
      <remap from="chatter" to="talk"/>
      <param name="~everyone" value="1"/>
      <group ns="g">
        <param name="gp" value="x"/>
        <remap from="a" to="b"/>
        <node pkg="p" type="t" name="n1" ns="sub" args="--x 1">
          <param name="priv" value="2"/>
          <param name="~tilde" value="3"/>
          <remap from="a" to="c"/>
          <rosparam>{r: 4}</rosparam>
          <env name="E" value="v"/>
        </node>
      </group>
      <node pkg="p" type="t" name="n2"/>
    </launch>""")
    n1, n2 = cfg.nodes
    assert n1.resolved_name == "/g/sub/n1" and n1.namespace == "/g/sub/" and n1.args == "--x 1"
    assert n1.remap_args == [("chatter", "talk"), ("a", "c")]
    assert n1.env_args == [("E", "v")]
    assert n2.remap_args == [("chatter", "talk")] and n2.env_args == []
    assert cfg.params["/g/gp"] == "x"
    for key, value in {"/g/sub/n1/priv": 2, "/g/sub/n1/tilde": 3, "/g/sub/n1/r": 4,
                       "/g/sub/n1/everyone": 1, "/n2/everyone": 1}.items():
        assert cfg.params[key] == value, key


def test_node_attributes():
    cfg = load("""<launch>
      <node pkg="p" type="t" name="a" output="screen" respawn="true" respawn_delay="2.5"
            cwd="node" launch-prefix="nice -n 5" clear_params="true"/>
      <node pkg="p" type="t" name="b" required="true"/>
    </launch>""")
    a, b = cfg.nodes
    assert (a.output, a.respawn, a.respawn_delay, a.cwd, a.launch_prefix) == ("screen", True, 2.5, "node", "nice -n 5")
    assert b.required and not b.respawn
    assert cfg.clear_params == ["/a/"]


def test_rosparam_load_subst_file_and_commands(tmp_path: Path):
    yaml_file = write(tmp_path, "p.yaml", "speed: 2\nnested: {deep: [1, 2]}\nangle: !degrees 180\n")
    cfg = load(f"""<launch>
      <arg name="v" default="9"/>
      <rosparam command="load" file="{yaml_file}" ns="cfg"/>
      <rosparam subst_value="true">val: $(arg v)</rosparam>
      <rosparam param="single">3.5</rosparam>
      <rosparam command="delete" param="old"/>
      <rosparam command="dump" file="{tmp_path}/out.yaml" param="cfg"/>
    </launch>""")
    assert cfg.params["/cfg/speed"] == 2 and cfg.params["/cfg/nested/deep"] == [1, 2]
    assert cfg.params["/cfg/angle"] == pytest.approx(math.pi)
    assert cfg.params["/val"] == 9 and cfg.params["/single"] == 3.5
    assert cfg.rosparam_commands == [("delete", "/old"), ("dump", f"{tmp_path}/out.yaml", "/cfg")]


def test_args_defaults_values_command_line_and_if_unless():
    text = """<launch>
      <arg name="use_a" default="true"/>
      <arg name="const" value="c"/>
      <arg name="n" default="1"/>
      <param name="n" value="$(arg n)"/>
      <param name="const" value="$(arg const)"/>
      <node pkg="p" type="t" name="a" if="$(arg use_a)"/>
      <node pkg="p" type="t" name="b" unless="$(arg use_a)"/>
      <group if="$(eval arg('n') > 1)"><param name="big" value="yes"/></group>
    </launch>"""
    cfg = load(text)
    assert [n.name for n in cfg.nodes] == ["a"] and cfg.params["/n"] == 1 and "/big" not in cfg.params
    cfg = load(text, ["use_a:=false", "n:=5"])
    assert [n.name for n in cfg.nodes] == ["b"] and cfg.params["/n"] == 5 and cfg.params["/big"] == "yes"
    with pytest.raises(LaunchError, match="cannot override arg 'const'"):
        load(text, ["const:=x"])


def test_include_with_ns_args_and_pass_all_args(tmp_path: Path):
    write(tmp_path, "inner.launch", """<launch>
      <arg name="who"/>
      <arg name="opt" default="d"/>
      <param name="who" value="$(arg who)"/>
      <param name="opt" value="$(arg opt)"/>
      <node pkg="p" type="t" name="$(arg who)"/>
    </launch>""")
    top = write(tmp_path, "top.launch", """<launch>
      <arg name="who" default="alice"/>
      <include file="$(dirname)/inner.launch" ns="one">
        <arg name="who" value="bob"/>
      </include>
      <include file="$(dirname)/inner.launch" ns="two" pass_all_args="true"/>
    </launch>""")
    cfg = load_launch(top)
    assert cfg.params["/one/who"] == "bob" and cfg.params["/one/opt"] == "d"
    assert cfg.params["/two/who"] == "alice"
    assert [n.resolved_name for n in cfg.nodes] == ["/one/bob", "/two/alice"]
    assert len(cfg.files) == 3


def test_include_errors(tmp_path: Path):
    write(tmp_path, "needs.launch", '<launch><arg name="x"/><param name="p" value="$(arg x)"/></launch>')
    top = write(tmp_path, "top.launch", '<launch>\n<include file="$(dirname)/needs.launch"/>\n</launch>')
    with pytest.raises(LaunchError) as err:
        load_launch(top)
    assert str(err.value) == f"{top}:2: included file [{tmp_path}/needs.launch] requires the 'x' arg to be set"
    unused = write(tmp_path, "unused.launch",
                   '<launch>\n<include file="$(dirname)/needs.launch">\n<arg name="x" value="1"/>'
                   '<arg name="y" value="2"/></include></launch>')
    with pytest.raises(LaunchError, match=r"unused args \[y\] for include of"):
        load_launch(unused)
    missing = write(tmp_path, "missing.launch", '<launch>\n<include file="/no/such.launch"/></launch>')
    with pytest.raises(LaunchError) as err:
        load_launch(missing)
    assert str(err.value) == (f"{missing}:2: cannot read included file [/no/such.launch]: "
                              "cannot read launch file: No such file or directory")
    broken = write(tmp_path, "broken.launch", "<launch>\n<param name='x'\n</launch>")
    includer = write(tmp_path, "includer.launch", f'<launch><include file="{broken}"/></launch>')
    with pytest.raises(LaunchError, match=rf"^{broken}:3: Invalid roslaunch XML syntax"):
        load_launch(includer)


def test_cyclic_include_is_detected(tmp_path: Path):
    write(tmp_path, "a.launch", '<launch>\n<include file="$(dirname)/b.launch"/>\n</launch>')
    write(tmp_path, "b.launch", '<launch>\n\n<include file="$(dirname)/a.launch"/>\n</launch>')
    with pytest.raises(LaunchError) as err:
        load_launch(str(tmp_path / "a.launch"))
    text = str(err.value)
    assert text.startswith(f"{tmp_path}/b.launch:3: cyclic include of [{tmp_path}/a.launch]")
    assert "\n" not in text


def test_missing_top_level_arg():
    with pytest.raises(LaunchError, match="requires the 'need' arg to be set"):
        load('<launch><arg name="need"/><param name="x" value="$(arg need)"/></launch>')
    cfg = load('<launch><arg name="need"/><param name="x" value="$(arg need)"/></launch>', ["need:=4"])
    assert cfg.params["/x"] == 4


@pytest.mark.slow
@pytest.mark.parametrize("xml,message", [
    ("<launch><param name='x' value='1'</launch>", "<string>:1: Invalid roslaunch XML syntax: not well-formed"),
    ("<notlaunch/>", "<string>:1: Invalid roslaunch XML syntax: no root <launch> tag"),
    ("<launch>\n<node pkg='p' type='t'/></launch>", "<string>:2: <node> tag is missing required attribute 'name'"),
    ("<launch><node pkg='p' type='t' name='n' respawn='true' required='true'/></launch>",
     "respawn and required cannot both be set to true"),
    ("<launch><node pkg='p' type='t' name='a/b'/></launch>", "node name cannot contain a namespace"),
    ("<launch><node pkg='p' type='t' name='n' output='file'/></launch>", "output must be one of 'log', 'screen'"),
    ("<launch><node pkg='p' type='t' name='n' respawn='yes'/></launch>", "invalid bool value for respawn: yes"),
    ("<launch><param name='x'/></launch>", "one and only one of value/textfile/binfile"),
    ("<launch><param name='x' value='1' type='float'/></launch>", "Unknown type 'float'"),
    ("<launch><param name='x' value='a' if='true' unless='true'/></launch>", "cannot set both 'if' and 'unless'"),
    ("<launch><param name='x' value='a' if='maybe'/></launch>", "is not a 'bool' type"),
    ("<launch><arg name='a' value='1' default='2'/></launch>", "one and only one of value/default"),
    ("<launch><arg name='a'/><arg name='a'/></launch>", "arg 'a' has already been declared"),
    ("<launch><param name='x' value='$(env NOT_SET_ANYWHERE)'/></launch>", "environment variable NOT_SET_ANYWHERE is not set"),
    ("<launch><rosparam>a: [1, 2</rosparam></launch>", "Error within YAML block"),
    ("<launch><rosparam>5</rosparam></launch>", "'param' attribute must be set for non-dictionary values"),
    ("<launch><node pkg='p' type='t' name='n'/><node pkg='p' type='t' name='n'/></launch>",
     "multiple nodes named [/n]"),
    ("<launch><remap from='' to='b'/></launch>", "remap from/to attributes cannot be empty"),
    ("<launch><group ns=''><param name='x' value='1'/></group></launch>", "<group> tag has an empty 'ns' attribute"),
    ("<launch><param name='x' command='/no/such/cmd'/></launch>", "no such command"),
    ("<launch><param name='x' command='false'/></launch>", "returned with code [1]"),
])
def test_bad_input_is_one_line(xml, message):
    with pytest.raises(LaunchError) as err:
        load(xml)
    assert message in str(err.value)
    assert "\n" not in str(err.value)


def test_unknown_tags_and_attributes_are_warnings():
    cfg = load("""<launch>
      <unknowntag/>
      <node pkg="p" type="t" name="n" bogus="1"><weird/></node>
      <param name="x" value="1" colour="red"/>
    </launch>""")
    assert cfg.warnings == [
        "[<string>:2] unrecognized tag unknowntag",
        "[<string>:3] unknown <node> attribute 'bogus'",
        "[<string>:3] unrecognized 'weird' child tag in the parent tag element <node>",
        "[<string>:4] unknown <param> attribute 'colour'",
    ]
    assert cfg.params["/x"] == 1 and cfg.nodes[0].name == "n"


def test_summary_matches_roslaunch_layout():
    cfg = load("""<launch>
      <param name="long" value="abcdefghijklmnopqrstuvwxyz"/>
      <param name="nl" type="str" value="x"/>
      <group ns="g"><node pkg="p" type="t" name="b"/></group>
      <node pkg="p" type="t" name="a"/>
    </launch>""")
    assert cfg.summary() == (
        "\nSUMMARY\n========\n\nPARAMETERS\n * /long: abcdefghijklmnopq...\n * /nl: x\n\n"
        "NODES\n  /\n    a (p/t)\n  /g/\n    b (p/t)\n")


def test_anon_names_shared_across_tags():
    cfg = load("""<launch>
      <node pkg="p" type="t" name="$(anon talker)"/>
      <param name="who" value="$(anon talker)"/>
    </launch>""")
    assert cfg.params["/who"] == cfg.nodes[0].name and cfg.nodes[0].name.startswith("talker_")


def test_absurd_nesting_is_an_error_not_a_crash(tmp_path: Path):
    deep = "<launch>" + "<group>" * 3000 + "</group>" * 3000 + "</launch>"
    with pytest.raises(LaunchError, match="nest too deeply"):
        load(deep)
    chain = 400  # distinct files, each including the next
    for i in range(chain):
        body = f'<include file="$(dirname)/f{i + 1}.launch"/>' if i + 1 < chain else ""
        write(tmp_path, f"f{i}.launch", f"<launch>{body}</launch>")
    with pytest.raises(LaunchError, match="nest too deeply"):
        load_launch(str(tmp_path / "f0.launch"))


def test_entity_declarations_are_refused():
    bomb = '<?xml version="1.0"?><!DOCTYPE l [<!ENTITY a "aaaaaaaaaa"><!ENTITY b "&a;&a;&a;">]><launch/>'
    with pytest.raises(LaunchError, match="entity declarations are not allowed"):
        load(bomb)


def test_test_retry_and_time_limit_are_checked():
    cfg = load('<launch><test test-name="t" pkg="p" type="x" retry="2" time-limit="5"/></launch>')
    assert (cfg.tests[0].retry, cfg.tests[0].time_limit) == (2, 5.0)
    with pytest.raises(LaunchError, match=r"'retry' must be a number: \[foo\]"):
        load('<launch><test test-name="t" pkg="p" type="x" retry="foo"/></launch>')
    with pytest.raises(LaunchError, match="'time-limit' must be a positive number"):
        load('<launch><test test-name="t" pkg="p" type="x" time-limit="-1"/></launch>')


def test_machine_attributes_and_what_roslaunch_refuses():
    cfg = load('<launch><machine name="m" address="a" timeout="1" user="u" ssh-port="2222" '
               'env-loader="/opt/env.sh"/></launch>')
    m = cfg.machines["m"]
    assert (m.timeout, m.user, m.ssh_port, m.env_loader) == (1.0, "u", 2222, "/opt/env.sh")
    for bad, text in [('timeout=""', "'timeout' cannot be empty"),
                      ('timeout="-1"', "'timeout' be a positive number"),
                      ('ros-root="/r"', "ros-\\* attributes are not supported since ROS Fuerte")]:
        with pytest.raises(LaunchError, match=text):
            load(f'<launch><machine name="m" address="a" {bad}/></launch>')
    with pytest.raises(LaunchError, match="<env> tag is not supported since ROS Fuerte"):
        load('<launch><machine name="m" address="a"><env name="A" value="1"/></machine></launch>')


def test_ignore_unset_args_keeps_what_came_before(tmp_path: Path):
    from minros.launch.loader import Loader

    text = '<launch><arg name="x"/><param name="a" value="1"/><param name="b" value="$(arg x)"/>' \
           '<param name="c" value="3"/></launch>'
    with pytest.raises(LaunchError, match="requires the 'x' arg to be set"):
        load(text)
    cfg = Loader(ignore_unset_args=True).load(write(tmp_path, "a.launch", text))
    assert cfg.params == {"/a": 1}
