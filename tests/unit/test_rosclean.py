"""rosclean (minros.cli.clean): check measures as du does, purge asks first and keeps the
newest logs under --size."""

from __future__ import annotations

import os
import shutil
import subprocess
import sys
import time
from pathlib import Path

import pytest

from minros.cli import clean


def make_logs(root: Path) -> Path:
    log = root / "log"
    for i, size in enumerate((300_000, 700_000, 1_500_000)):
        run = log / f"run{i}"
        run.mkdir(parents=True)
        (run / "node.log").write_bytes(os.urandom(size))
        os.utime(run, (time.time() - 100 + i, time.time() - 100 + i))
    return log


def rosclean(env_home: Path, *args: str, stdin: str = "") -> subprocess.CompletedProcess:
    env = {k: v for k, v in os.environ.items() if not k.startswith("ROS_")}
    env["ROS_HOME"] = str(env_home)
    return subprocess.run([sys.executable, "-m", "minros", "clean", *args], input=stdin,
                          capture_output=True, text=True, env=env, timeout=60)


@pytest.mark.slow
def test_check_prints_what_du_prints(tmp_path: Path):
    log = make_logs(tmp_path)
    out = rosclean(tmp_path, "check")
    assert out.returncode == 0, out.stderr
    if shutil.which("du"):
        du = subprocess.run(["du", "-sh", str(log)], capture_output=True, text=True).stdout.split()[0]
        assert out.stdout == f"{du} ROS node logs\n"
    assert clean.get_disk_usage(str(log)) >= 2_500_000


@pytest.mark.slow
def test_purge_asks_and_n_keeps_everything(tmp_path: Path):
    log = make_logs(tmp_path)
    out = rosclean(tmp_path, "purge", stdin="maybe\nn\n")
    assert f"Okay to perform:\n\nrm -rf {log}\n(y/n)?" in out.stdout
    assert log.is_dir() and len(list(log.iterdir())) == 3


@pytest.mark.slow
def test_purge_to_size_drops_the_oldest(tmp_path: Path):
    log = make_logs(tmp_path)
    out = rosclean(tmp_path, "purge", "-y", "--size", "2")
    assert "Purging ROS node logs until directory size is at most 2 MB (currently 2 MB)." in out.stdout
    assert sorted(p.name for p in log.iterdir()) == ["run2"]
    out = rosclean(tmp_path, "purge", "-y", "--size", "5")
    assert "which is already below the requested threshold of 5 MB" in out.stdout


@pytest.mark.slow
def test_purge_y_removes_the_log_folder(tmp_path: Path):
    log = make_logs(tmp_path)
    assert rosclean(tmp_path, "purge", "-y").returncode == 0
    assert not log.exists()


@pytest.mark.parametrize("size, text", [(0, "0"), (1023, "1023"), (1024, "1.0K"), (4097, "4.1K"),
                                        (10 * 1024 + 1, "11K"), (5 * 1024 ** 2, "5.0M")])
def test_human_size_rounds_up_as_du(size: int, text: str):
    assert clean.human_size(size) == text
