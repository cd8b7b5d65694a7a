"""`rostopic hz` and `rostopic echo` keep up with a 1 kHz topic and a 30 Hz 1080p image topic.

Bounds are generous (the CI machine is shared); the figures measured on an idle machine are
in the CLI report: hz reads ~1000 Hz and ~30 Hz, echo prints every message."""

from __future__ import annotations

import re
import signal
import subprocess
import time
from pathlib import Path

import pytest

from support import PYTHON, Proc, free_port, ros_env, wait_for_master

PUB = str(Path(__file__).resolve().parent / "cli_rate_pub.py")
BIN = Path(PYTHON).parent


@pytest.fixture(scope="module")
def env(tmp_path_factory):
    home = tmp_path_factory.mktemp("cli_rates")
    (home / "log").mkdir()
    port = free_port()
    env = ros_env(port, home)
    master = Proc([PYTHON, "-m", "minros.master", "-p", str(port)], env)
    try:
        wait_for_master(port)
        yield env
    finally:
        master.stop()


def _run_for(argv: list, env: dict, seconds: float) -> str:
    proc = subprocess.Popen(argv, env=env, stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                            start_new_session=True)
    time.sleep(seconds)  # measuring for a fixed wall-clock span is the point here
    proc.send_signal(signal.SIGINT)
    try:
        out, _ = proc.communicate(timeout=10)
    except subprocess.TimeoutExpired:
        proc.kill()
        out, _ = proc.communicate()
    return out.decode("utf-8", "replace")


def _last_rate(text: str) -> float:
    rates = re.findall(r"average rate: ([\d.]+)", text)
    assert rates, text
    return float(rates[-1])


@pytest.mark.parametrize("kind,rate,echo_args", [("small", 1000, []), ("image", 30, ["--noarr"])])
@pytest.mark.timing
def test_hz_and_echo_keep_up(env: dict, kind: str, rate: int, echo_args: list) -> None:
    topic = "/fast" if kind == "small" else "/image"
    pub = Proc([PYTHON, PUB, kind, str(rate)], env)
    try:
        pub.read_until("ready", 30)
        hz = _run_for([str(BIN / "rostopic"), "hz", topic], env, 2.0)
        measured = _last_rate(hz)
        assert 0.3 * rate < measured < 1.3 * rate, hz
        start = time.monotonic()
        echo = _run_for([str(BIN / "rostopic"), "echo", *echo_args, topic], env, 2.0)
        elapsed = time.monotonic() - start
        printed = echo.count("\n---\n")
        # the tool needs ~0.5 s to start and subscribe; then it must print at the topic's rate
        assert printed >= 0.3 * rate * (elapsed - 1.0), (printed, elapsed)
    finally:
        pub.stop()
