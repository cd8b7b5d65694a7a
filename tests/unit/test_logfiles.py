"""Bounded log files (minros.logfiles): ROS's rotation sizes, truncated lines."""

from __future__ import annotations

import logging
import logging.handlers

import pytest

from minros import logfiles
from minros.logfiles import RotatingLog


def test_rospy_and_rosout_sizes():
    # /etc/ros/python_logging.conf: RotatingFileHandler(..., 'a', 50000000, 4); rosout.cpp: 100 MiB x 10
    assert (logfiles.NODE_LOG_MAX_BYTES, logfiles.NODE_LOG_BACKUPS) == (50000000, 4)
    assert (logfiles.ROSOUT_MAX_BYTES, logfiles.ROSOUT_BACKUPS) == (100 * 1024 * 1024, 10)


def test_truncate():
    assert logfiles.truncate("short", 10) == "short"
    assert logfiles.truncate("x" * 25, 10) == "x" * 10 + "... [15 more characters]"


def test_rotating_handler_rotates_and_truncates(tmp_path):
    handler = logfiles.rotating_handler(tmp_path / "master.log", "%(message)s", max_bytes=20000,
                                        backups=2)
    assert isinstance(handler, logging.handlers.RotatingFileHandler)
    logger = logging.getLogger("test_logfiles")
    logger.propagate = False
    logger.addHandler(handler)
    try:
        for i in range(20):
            logger.warning("+PARAM [/p%d] by %s", i, "/" + "x" * 100000)
    finally:
        logger.removeHandler(handler)
        handler.close()
    files = sorted(p.name for p in tmp_path.iterdir())
    assert files == ["master.log", "master.log.1", "master.log.2"]
    assert all(p.stat().st_size <= 20000 for p in tmp_path.iterdir())
    last = (tmp_path / "master.log").read_text().splitlines()[-1]
    assert last.startswith("+PARAM [/p19] by /xxx") and last.endswith("... [91826 more characters]")


def test_rotating_log_rotation_and_truncation(tmp_path):
    log = RotatingLog(tmp_path / "rosout.log", max_size=100, backups=2, limit=30)
    for i in range(10):
        log.write(f"line {i:02d} " + "x" * 40 + "\n")
    log.close()
    assert (tmp_path / "rosout.log.1").exists() and (tmp_path / "rosout.log.2").exists()
    assert not (tmp_path / "rosout.log.3").exists()
    text = (tmp_path / "rosout.log").read_text()
    assert text.endswith("line 09 " + "x" * 22 + "... [18 more characters]\n")


def test_rotate_copy_truncate_keeps_the_writer_appending(tmp_path):
    path = tmp_path / "talker-1-stdout.log"
    writer = open(path, "a")  # as roslaunch hands it to a node
    try:
        writer.write("a" * 100)
        writer.flush()
        assert not logfiles.rotate_copy_truncate(path, max_bytes=100, backups=2)
        writer.write("b")
        writer.flush()
        assert logfiles.rotate_copy_truncate(path, max_bytes=100, backups=2)
        assert (tmp_path / "talker-1-stdout.log.1").read_text() == "a" * 100 + "b"
        writer.write("next line\n")
        writer.flush()
        assert path.read_text() == "next line\n"  # at the start of the emptied file, no hole
        writer.write("c" * 200)
        writer.flush()
        assert logfiles.rotate_copy_truncate(path, max_bytes=100, backups=2)
        writer.write("d" * 200)
        writer.flush()
        assert logfiles.rotate_copy_truncate(path, max_bytes=100, backups=2)
        assert sorted(p.name for p in tmp_path.iterdir()) == [
            "talker-1-stdout.log", "talker-1-stdout.log.1", "talker-1-stdout.log.2"]
        assert (tmp_path / "talker-1-stdout.log.1").read_text() == "d" * 200
    finally:
        writer.close()
    assert not logfiles.rotate_copy_truncate(tmp_path / "missing.log")


@pytest.mark.slow
def test_roslaunch_rotates_the_console_logs_of_its_processes(tmp_path, monkeypatch):
    import sys
    import time

    from minros.launch.runner import LaunchProcess

    monkeypatch.setattr(logfiles, "NODE_LOG_MAX_BYTES", 10000)
    monkeypatch.setattr(logfiles, "NODE_LOG_BACKUPS", 2)
    # three rounds of 15 kB, each waiting for the test to rotate before the next one
    chatty = ("import os, sys, time\n"
              "for r in range(3):\n"
              "    for i in range(300): print('round', r, 'line', i, 'x' * 30, flush=True)\n"
              "    print('end of round', r, flush=True)\n"
              "    while not os.path.exists(sys.argv[1] + str(r)): time.sleep(0.01)\n")
    go = tmp_path / "go"
    proc = LaunchProcess("chatty", [sys.executable, "-c", chatty, str(go)], {}, str(tmp_path),
                         log_dir=tmp_path / "log", screen=False)
    stdout = tmp_path / "log" / "chatty-stdout.log"
    proc.start()
    try:
        for r in range(3):
            deadline = time.monotonic() + 10
            while f"end of round {r}" not in stdout.read_text() and time.monotonic() < deadline:
                time.sleep(0.01)
            proc.rotate_logs()  # what roslaunch's monitor does once a second
            assert stdout.stat().st_size == 0
            (tmp_path / f"go{r}").touch()
    finally:
        proc.stop(1, 1, print)
    names = sorted(p.name for p in stdout.parent.glob("chatty-stdout.log*"))
    assert names == ["chatty-stdout.log", "chatty-stdout.log.1", "chatty-stdout.log.2"]
    assert (stdout.parent / "chatty-stdout.log.1").read_text().endswith("end of round 2\n")
    assert (stdout.parent / "chatty-stdout.log.2").read_text().startswith("round 1 line 0 ")
