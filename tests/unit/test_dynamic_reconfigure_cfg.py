""".cfg scripts -> <pkg>.cfg.<Name>Config: the generated contents, one-line errors naming file and
line, the import hook, catkin_make; the configuration <-> message encoding as pure functions."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import pytest

from minros.dynamic_reconfigure import encoding
from minros.dynamic_reconfigure.generator import CfgError, module_namespace, run_cfg
from support import run_python

#: the dynamic_reconfigure wiki tutorial's .cfg (tests/examples/library_tutorials)
TUTORIAL_CFG = (Path(__file__).resolve().parent.parent / "examples" / "library_tutorials"
                / "dynamic_tutorials" / "cfg" / "Tutorials.cfg").read_text()

GROUPS_CFG = '''PACKAGE = "grouped_pkg"
from dynamic_reconfigure.parameter_generator_catkin import *
gen = ParameterGenerator()
gen.add("rate", double_t, 1, "Loop rate", 10, 0.5)
motors = gen.add_group("Motors", type="tab")
motors.add("gain", double_t, 8, "Motor gain", 1.0, 0, 2.5)
limits = motors.add_group("Speed limits", type="collapse", state=False)
limits.add("enabled", bool_t, 32, "Limits on", True)
camera = gen.add_group("Camera")
camera.add("exposure", int_t, 64, "Exposure", -3, -10, 10)
exit(gen.generate(PACKAGE, "node", "Groups"))
'''


def _package(root: Path, name: str, cfgs: dict) -> Path:
    pkg = root / name
    (pkg / "cfg").mkdir(parents=True)
    (pkg / "package.xml").write_text(f"<package format='2'><name>{name}</name></package>\n")
    for stem, text in cfgs.items():
        (pkg / "cfg" / f"{stem}.cfg").write_text(text)
    return pkg


def test_tutorial_cfg_gives_the_generated_module_contents(tmp_path: Path) -> None:
    pkg = _package(tmp_path, "dynamic_tutorials", {"Tutorials": TUTORIAL_CFG})
    ns = module_namespace(run_cfg(pkg / "cfg" / "Tutorials.cfg"))
    assert ns["defaults"] == {"int_param": 50, "double_param": 0.5, "str_param": "Hello World",
                              "bool_param": True, "size": 1}
    assert ns["min"] == {"int_param": 0, "double_param": 0.0, "str_param": "", "bool_param": False,
                         "size": 0}
    assert ns["max"] == {"int_param": 100, "double_param": 1.0, "str_param": "", "bool_param": True,
                         "size": 3}
    assert type(ns["defaults"]["double_param"]) is float and type(ns["min"]["double_param"]) is float
    assert ns["type"]["size"] == "int" and ns["all_level"] == 0
    assert [ns[f"Tutorials_{c}"] for c in ("Small", "Medium", "Large", "ExtraLarge")] == [0, 1, 2, 3]
    root = ns["config_description"]
    assert (root["name"], root["id"], root["class"], root["field"], root["lower"]) == (
        "Default", 0, "DEFAULT", "default", "groups")
    size = root["parameters"][4]
    assert size["edit_method"].startswith("{'enum': [{'name': 'Small', 'type': 'int', 'value': 0, "
                                          "'srcline': 13, 'srcfile': 'Tutorials.cfg'")
    assert size["srcline"] == 19 and size["srcfile"] == "Tutorials.cfg"


def test_groups_ids_classes_and_infinite_bounds(tmp_path: Path) -> None:
    pkg = _package(tmp_path, "grouped_pkg", {"Groups": GROUPS_CFG})
    ns = module_namespace(run_cfg(pkg / "cfg" / "Groups.cfg"))
    root = ns["config_description"]
    motors, camera = root["groups"]
    limits = motors["groups"][0]
    assert [(g["name"], g["id"], g["parent"]) for g in (motors, limits, camera)] == [
        ("Motors", 1, 0), ("Speed_limits", 2, 1), ("Camera", 3, 0)]
    assert (limits["class"], limits["parentclass"], limits["field"], limits["parentname"]) == (
        "DEFAULT::MOTORS::SPEED_LIMITS", "DEFAULT::MOTORS", "DEFAULT::MOTORS::speed_limits", "Motors")
    assert limits["state"] is False and limits["cstate"] == "false" and limits["type"] == "collapse"
    assert ns["max"]["rate"] == float("inf") and ns["min"]["gain"] == 0.0
    assert ns["all_level"] == 1 | 8 | 32 | 64
    assert [p["name"] for p in encoding.extract_params(root)] == ["rate", "gain", "enabled", "exposure"]


@pytest.mark.parametrize("body, line, text", [
    ('gen.add("x", int_t, 0, "d", "fifty")\n', 4, "TypeError: 'x' has type int, but default is 'fifty'"),
    ('gen.add("x", int_t, 0, "d", True)\n', 4, "TypeError: 'x' has type int, but default is True"),
    ('gen.add("2x", int_t, 0, "d")\n', 4, "The name of field '2x' does not follow"),
    ('gen.add("s", str_t, 0, "d", "a", "b")\n', 4, "Max or min specified for s, which is of 'str' type"),
    ('gen.add("f", "float", 0, "d")\n', 4, "'f' has unknown type 'float'"),
    ('gen.const("c", int_t, 1, "it\'s")\n', 4, "quotes not allowed in description string"),
    ('gen.enum([gen.const("a", int_t, 1, "a"), gen.const("b", str_t, "b", "b")], "e")\n', 4,
     "Inconsistent types in enum!"),
    ('gen.add("x", int_t, 0, "d"\n', 4, "SyntaxError: "),
    ('undefined_name\n', 4, "NameError: name 'undefined_name' is not defined"),
])
def test_broken_cfg_is_one_line_naming_file_and_line(tmp_path: Path, body: str, line: int,
                                                     text: str) -> None:
    head = "from dynamic_reconfigure.parameter_generator_catkin import *\ngen = ParameterGenerator()\n\n"
    path = tmp_path / "Bad.cfg"
    path.write_text(head + body + 'exit(gen.generate("p", "n", "Bad"))\n')
    with pytest.raises(CfgError) as err:
        run_cfg(path)
    message = str(err.value)
    assert "\n" not in message
    assert message.startswith(f"{path}:{line}: ")
    assert text in message


def test_cfg_that_never_generates_or_exits_nonzero(tmp_path: Path) -> None:
    path = tmp_path / "Quiet.cfg"
    path.write_text("from dynamic_reconfigure.parameter_generator_catkin import *\n"
                    "gen = ParameterGenerator()\n")
    with pytest.raises(CfgError, match=r"Quiet.cfg: the script never called gen.generate"):
        run_cfg(path)
    path.write_text("import sys\nsys.exit(3)\n")
    with pytest.raises(CfgError, match=r"exited with status 3"):
        run_cfg(path)


@pytest.mark.slow
def test_running_a_cfg_by_hand_says_how_it_is_used(tmp_path: Path) -> None:
    path = tmp_path / "Tutorials.cfg"
    path.write_text(TUTORIAL_CFG)
    out = subprocess.run([sys.executable, str(path)], capture_output=True, text=True, timeout=60)
    assert out.returncode == 1
    assert out.stderr.startswith("ahhhh! Unexpected command line syntax!")


@pytest.mark.slow
def test_import_hook_serves_cfg_modules(tmp_path: Path) -> None:
    _package(tmp_path / "src", "dynamic_tutorials", {"Tutorials": TUTORIAL_CFG})
    _package(tmp_path / "src", "other_pkg", {"Named": GROUPS_CFG})  # generates GroupsConfig
    code = (
        "import rospy\n"
        "from dynamic_tutorials.cfg import TutorialsConfig\n"
        "import dynamic_tutorials.cfg.TutorialsConfig as again\n"
        "from other_pkg.cfg import GroupsConfig\n"
        "assert again is TutorialsConfig\n"
        "print(TutorialsConfig.defaults['str_param'], TutorialsConfig.Tutorials_Large, "
        "GroupsConfig.level['exposure'])\n"
        "try:\n"
        "    from dynamic_tutorials.cfg import MissingConfig\n"
        "except ImportError as exc:\n"
        "    print('missing:', exc)\n"
    )
    out = run_python(code, {"ROS_PACKAGE_PATH": str(tmp_path / "src")})
    assert out.returncode == 0, out.stderr
    lines = out.stdout.splitlines()
    assert lines[0] == "Hello World 2 64"
    assert lines[1].startswith("missing: ") and "cfg/Missing.cfg" in lines[1]


@pytest.mark.slow
def test_import_of_a_broken_cfg_raises_one_line_import_error(tmp_path: Path) -> None:
    broken = TUTORIAL_CFG.replace('"Hello World")', '"Hello World", 1, 2)')
    pkg = _package(tmp_path / "src", "broken_pkg", {"Tutorials": broken})
    out = run_python("import rospy\ntry:\n    from broken_pkg.cfg import TutorialsConfig\n"
                     "except ImportError as exc:\n    print(type(exc).__name__, exc)\n",
                     {"ROS_PACKAGE_PATH": str(tmp_path / "src")})
    assert out.returncode == 0, out.stderr
    assert out.stdout == (f"ImportError {pkg / 'cfg' / 'Tutorials.cfg'}:10: Exception: Max or min "
                          "specified for str_param, which is of 'str' type\n")


@pytest.mark.slow
def test_catkin_make_checks_cfg_and_writes_modules(tmp_path: Path) -> None:
    from minros.workspace import catkin

    ws = tmp_path / "ws"
    pkg = _package(ws / "src", "dynamic_tutorials", {"Tutorials": TUTORIAL_CFG})
    lines: list = []
    catkin.make_workspace(ws, out=lines.append)
    assert "Generating reconfiguration files for Tutorials in dynamic_tutorials" in lines
    devel = ws / "devel" / "lib" / "python3" / "dist-packages"
    # the devel module reruns the .cfg on import: an edit needs no rebuild
    (pkg / "cfg" / "Tutorials.cfg").write_text(TUTORIAL_CFG.replace("50,  0, 100", "42,  0, 100"))
    env = {"PYTHONPATH": str(devel), "ROS_PACKAGE_PATH": ""}
    out = run_python("from dynamic_tutorials.cfg import TutorialsConfig as T\nprint(T.defaults['int_param'])",
                     env)
    assert out.returncode == 0, out.stderr
    assert out.stdout == "42\n"
    (pkg / "cfg" / "Tutorials.cfg").write_text(TUTORIAL_CFG.replace('"Hello World")', '"Hi", 1)'))
    with pytest.raises(catkin.WorkspaceError) as err:
        catkin.make_workspace(ws, out=lambda s: None)
    assert str(err.value).startswith(f"{pkg / 'cfg' / 'Tutorials.cfg'}:10: Exception: Max or min")


# --------------------------------------------------------------------------- encoding

def _tutorial_type(tmp_path: Path):
    import types

    path = tmp_path / "Tutorials.cfg"
    path.write_text(TUTORIAL_CFG)
    return types.SimpleNamespace(**module_namespace(run_cfg(path)))


def test_description_and_config_round_trip(tmp_path: Path) -> None:
    kind = _tutorial_type(tmp_path)
    descr = encoding.encode_description(kind)
    assert [g.name for g in descr.groups] == ["Default"]
    assert [p.name for p in descr.groups[0].parameters] == [
        "int_param", "double_param", "str_param", "bool_param", "size"]
    assert [(p.name, p.value) for p in descr.dflt.doubles] == [("double_param", 0.5)]
    tree = encoding.decode_description(descr)
    assert tree["parameters"][0] == {
        "name": "int_param", "min": 0, "max": 100, "default": 50, "type": "int", "level": 0,
        "description": "An Integer parameter", "edit_method": ""}
    config = dict(kind.defaults)
    config["groups"] = encoding.get_tree(descr)
    start = encoding.initial_config(encoding.encode_config(config), kind.config_description)
    # ROS's order: bools, ints, strs, doubles, then the group tree with its values
    assert list(start) == ["bool_param", "int_param", "size", "str_param", "double_param", "groups"]
    assert start.groups.parameters == {"int_param": 50, "double_param": 0.5,
                                       "str_param": "Hello World", "bool_param": True, "size": 1}
    msg = encoding.encode_config(start)
    assert [(g.name, g.state, g.id, g.parent) for g in msg.groups] == [("Default", True, 0, 0)]
    back = encoding.decode_config(msg, tree)
    assert back["int_param"] == 50 and back.groups["str_param"] == "Hello World"


def test_cyclic_group_tree_from_a_peer_is_bounded() -> None:
    from dynamic_reconfigure.msg import Config, GroupState

    msg = Config(groups=[GroupState("Default", True, 0, 0), GroupState("a", True, 1, 2),
                         GroupState("b", True, 2, 1)])
    tree = encoding.get_tree(msg)
    assert tree["name"] == "Default" and tree["groups"] == {}
