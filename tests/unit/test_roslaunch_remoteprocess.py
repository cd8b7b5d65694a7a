"""roslaunch.remoteprocess: the SSH known_hosts check (plain and hashed entries, ports, the
ROSLAUNCH_SSH_UNKNOWN override) and the SSH child that says minros launches locally only."""

from __future__ import annotations

import base64
import hashlib
import hmac
from pathlib import Path

import pytest

from minros.launch import rosserver


def _hashed(host: str, salt: bytes = b"0123456789abcdefghij") -> str:
    mac = hmac.new(salt, host.encode(), hashlib.sha1).digest()
    return f"|1|{base64.b64encode(salt).decode()}|{base64.b64encode(mac).decode()}"


def test_known_hosts_plain_hashed_wildcard_and_port(tmp_path: Path) -> None:
    known = tmp_path / "known_hosts"
    known.write_text("# comment\n"
                     "alpha,10.0.0.1 ssh-ed25519 AAAA\n"
                     f"{_hashed('beta')} ssh-ed25519 AAAA\n"
                     "[gamma]:2222 ssh-rsa AAAA\n"
                     "*.lab ssh-rsa AAAA\n"
                     "@revoked delta ssh-rsa AAAA\n")
    files = [str(known), str(tmp_path / "absent")]
    assert rosserver.is_known_host("alpha", 22, files)
    assert rosserver.is_known_host("10.0.0.1", 22, files)
    assert rosserver.is_known_host("beta", 22, files)
    assert not rosserver.is_known_host("beta", 2200, files)
    assert rosserver.is_known_host("gamma", 2222, files)
    assert not rosserver.is_known_host("gamma", 22, files)
    assert rosserver.is_known_host("robot.lab", 22, files)
    assert not rosserver.is_known_host("omega", 22, files)


def test_ssh_check_known_hosts_advice(monkeypatch: pytest.MonkeyPatch, tmp_path: Path) -> None:
    monkeypatch.setenv("HOME", str(tmp_path))
    monkeypatch.delenv("ROSLAUNCH_SSH_UNKNOWN", raising=False)
    monkeypatch.setattr(rosserver, "is_known_host", lambda host, port=22, files=None: False)
    text = rosserver.ssh_check_known_hosts(None, "robot", 2222, "pi")
    assert text is not None
    assert text.startswith("robot is not in your SSH known_hosts file.\n")
    assert "  ssh -p 2222 pi@robot\n" in text
    assert rosserver.ssh_check_known_hosts(None, "robot", 22).count("ssh robot\n") == 1
    monkeypatch.setenv("ROSLAUNCH_SSH_UNKNOWN", "1")
    assert rosserver.ssh_check_known_hosts(None, "robot", 22) is None


class _Machine:
    name, address, env_loader = "arm", "10.1.2.3", "/opt/ros/env.sh"


def test_ssh_child_builds_roslaunchs_command_and_refuses_to_start(
        capsys: pytest.CaptureFixture[str]) -> None:
    child = rosserver.SSHChildROSLaunchProcess("run1", "arm-0", "http://here:1234/", _Machine())
    assert child.args == ["/opt/ros/env.sh", "roslaunch", "-c", "arm-0", "-u", "http://here:1234/",
                          "--run_id", "run1", "--sigint-timeout", "15.0", "--sigterm-timeout", "2.0"]
    assert child.is_alive()  # not started yet
    assert child.start() is False
    assert not child.is_alive()
    err = capsys.readouterr().err
    assert "remote[arm-0]: failed to launch on arm:" in err
    assert "minros launches nodes on this machine only" in err and "[10.1.2.3]" in err
    child.stop()
    no_loader = _Machine()
    no_loader.env_loader = None
    with pytest.raises(ValueError, match="env_loader must have been assigned"):
        rosserver.SSHChildROSLaunchProcess("run1", "arm-0", "http://here:1234/", no_loader)
