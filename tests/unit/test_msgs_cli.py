"""``minros msg`` / ``minros srv`` (rosmsg / rossrv) called in-process."""

from __future__ import annotations

import io

import pytest

from minros.cli import msg as msg_cli
from minros.cli import srv as srv_cli


def test_show_expanded_and_raw(capsys) -> None:
    assert msg_cli.main(["show", "geometry_msgs/Vector3Stamped"], "rosmsg") == 0
    assert capsys.readouterr().out == (
        "std_msgs/Header header\n  uint32 seq\n  time stamp\n  string frame_id\n"
        "geometry_msgs/Vector3 vector\n  float64 x\n  float64 y\n  float64 z\n\n")
    assert msg_cli.main(["show", "-r", "turtlesim/Pose"], "rosmsg") == 0
    assert capsys.readouterr().out == (
        "float32 x\nfloat32 y\nfloat32 theta\n\nfloat32 linear_velocity\nfloat32 angular_velocity\n")


def test_show_reads_type_from_stdin(capsys, monkeypatch) -> None:
    monkeypatch.setattr("sys.stdin", io.StringIO("\ngeometry_msgs/Twist\n"))
    assert msg_cli.main(["show"], "rosmsg") == 0
    assert capsys.readouterr().out.startswith("geometry_msgs/Vector3 linear\n  float64 x\n")


def test_search_by_base_name_and_md5(capsys) -> None:
    assert msg_cli.main(["md5", "Pose"], "rosmsg") == 0
    out = capsys.readouterr().out
    assert "[geometry_msgs/Pose]: e45d45a5a1ce597b249e23fb30fc871f" in out
    assert "[turtlesim/Pose]: 863b248d5016ca62ea2e895ae5265cf9" in out


def test_gen_prints_the_class_source(capsys) -> None:
    assert msg_cli.main(["gen", "std_msgs/Header"], "minros msg") == 0
    out = capsys.readouterr().out
    assert "class Header(_Message):" in out and "def _deserialize_from(self, view, end):" in out
    assert msg_cli.main(["gen", "--numpy", "std_msgs/Float32MultiArray"], "minros msg") == 0
    assert "_numpy_view('f'" in capsys.readouterr().out


def test_lists(capsys) -> None:
    assert msg_cli.main(["packages"], "rosmsg") == 0
    packages = capsys.readouterr().out.split()
    assert packages == sorted(packages) and "std_msgs" in packages and "std_srvs" not in packages
    assert srv_cli.main(["packages", "-s"], "rossrv") == 0
    assert "std_srvs" in capsys.readouterr().out.split()
    assert srv_cli.main(["package", "turtlesim"], "rossrv") == 0
    assert capsys.readouterr().out.split() == [
        "turtlesim/Kill", "turtlesim/SetPen", "turtlesim/Spawn", "turtlesim/TeleportAbsolute",
        "turtlesim/TeleportRelative"]
    assert msg_cli.main(["list"], "rosmsg") == 0
    listed = capsys.readouterr().out.split()
    assert "sensor_msgs/Image" in listed and "nav_msgs/GetMapActionGoal" in listed


def test_srv_show(capsys) -> None:
    assert srv_cli.main(["show", "rospy_tutorials/AddTwoInts"], "rossrv") == 0
    assert capsys.readouterr().out == "int64 a\nint64 b\n---\nint64 sum\n\n"
    assert srv_cli.main(["md5", "turtlesim/Spawn"], "rossrv") == 0
    assert capsys.readouterr().out == "0b2d2e872a8e2887d5ed626f2bf2c561\n"


@pytest.mark.parametrize("argv", [
    ["show", "std_msgs/Nope"], ["md5", "nopkg/X"], ["show", "NoSuchTypeAnywhere"],
    ["show", "std_msgs.String"], ["package", "nopkg"],
])
def test_errors_are_one_line(capsys, argv) -> None:
    assert msg_cli.main(argv, "rosmsg") != 0
    captured = capsys.readouterr()
    assert captured.out == "" and len(captured.err.strip().splitlines()) == 1


def test_malformed_definition_is_one_line(capsys, tmp_path, monkeypatch) -> None:
    pkg = tmp_path / "broken_pkg"
    (pkg / "msg").mkdir(parents=True)
    (pkg / "package.xml").write_text("<package><name>broken_pkg</name></package>")
    (pkg / "msg" / "Bad.msg").write_text("int32 x\nint32 x\n")
    monkeypatch.setenv("ROS_PACKAGE_PATH", str(tmp_path))
    assert msg_cli.main(["show", "broken_pkg/Bad"], "rosmsg") == 1
    err = capsys.readouterr().err
    assert len(err.strip().splitlines()) == 1 and "Bad.msg:2" in err
