"""roswtf's installation, package and stack rules (roswtf.packages, stacks, rosdep_db,
py_pip_deb_checks, plugins) on packages made for the test."""

from __future__ import annotations

from pathlib import Path

import pytest

from minros import packages
from minros.cli import wtfsource
from minros.cli.wtf import WtfContext


@pytest.fixture
def pkgs(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> Path:
    old = tmp_path / "old_pkg"
    (old / "msg").mkdir(parents=True)
    (old / "msg" / "A.msg").write_text("int32 a\n")
    (old / "manifest.xml").write_text(
        '<package><description>x</description><license>BSD</license><export>'
        '<cpp cflags="-I${prefix}/msg/cpp" lflags="-L${prefix}/lib -lold"/>'
        '<roswtf plugin="json"/></export></package>')
    (old / "CMakeLists.txt").write_text("rospack(other_pkg)\n")
    good = tmp_path / "good_pkg"
    good.mkdir()
    (good / "package.xml").write_text("<package><name>good_pkg</name></package>")
    (good / "CMakeLists.txt").write_text("rosbuild_init()\n")
    monkeypatch.setenv("ROS_PACKAGE_PATH", str(tmp_path))
    monkeypatch.setenv("HOME", str(tmp_path))
    packages.list_packages(refresh=True)
    return tmp_path


def test_package_rules_find_rosbuild_leftovers(pkgs: Path) -> None:
    ctx = WtfContext.from_env()
    ctx.pkgs = ["old_pkg", "good_pkg"]
    assert wtfsource.cmakelists_package_valid(ctx) == ["old_pkg"]
    assert wtfsource.manifest_msg_srv_export(ctx) == ["old_pkg: -I${prefix}/msg/cpp"]
    lib = pkgs / "old_pkg" / "lib"
    assert wtfsource.manifest_rpath_flags(ctx) == [
        f'old_pkg: found flag "-L{lib}", but no matching "-Wl,-rpath,{lib}"']
    assert wtfsource._check_for_rpath_flags("p", "-L/a -Wl,-rpath,/a") is None
    wtfsource.wtf_check_packages(ctx)
    assert [e.msg.splitlines()[0] for e in ctx.errors] == [
        "The following packages have rpath issues in manifest.xml:"]
    assert len(ctx.warnings) == 2


def test_rosdep_and_python_module_rules(pkgs: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    ctx = WtfContext.from_env()
    wtfsource.wtf_check_rosdep(ctx)
    assert [w.msg for w in ctx.warnings] == [
        "ROS Dep database not updated: Please update rosdep database with 'rosdep update'."]
    index = pkgs / ".ros" / "rosdep" / "sources.cache" / "index"
    index.parent.mkdir(parents=True)
    index.write_text("")
    assert wtfsource.rosdep_database_updated_check(ctx) is None
    monkeypatch.setattr(wtfsource, "py_to_deb_core_packages",
                        {"json": "python3", "no_such_module_x": "python3-x"})
    assert wtfsource.python_module_install_check(ctx) == "no_such_module_x -- "
    assert wtfsource.is_a_pip_path_on_ubuntu("/usr/local/lib/python3/dist-packages/x.py")


def test_plugins_load_exported_modules(pkgs: Path, capsys: pytest.CaptureFixture[str],
                                       monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setattr(packages, "plugins", lambda pkg, attrib="plugin": [
        ("old_pkg", "json"), ("tf", "tf.tfwtf"), ("bad", "no_such_module_y")])
    static, online = wtfsource.load_plugins()
    err = capsys.readouterr().err
    assert "Cannot load plugin [json]: no 'roswtf_plugin_static'" in err
    assert "Unable to load plugin [no_such_module_y] from package [bad]" in err
    assert [f.__name__ for f in online] == ["roswtf_plugin_online"] and static == []
