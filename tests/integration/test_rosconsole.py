"""rosconsole: the /rosout stream filtered by level and logger name, and a node's loggers listed,
read and set through its ~get_loggers/~set_logger_level services."""

from __future__ import annotations

import subprocess
import xmlrpc.client
from pathlib import Path

import pytest

from minros.cli.console import ConsoleEcho
from minros.msgs import get_message_class
from support import PYTHON, Proc, ros_env, wait_until

NOISY = '''
import rospy
rospy.init_node("noisy")
rate = rospy.Rate(20)
while not rospy.is_shutdown():
    rospy.logwarn("careful")
    rospy.logdebug("details")
    try:
        rate.sleep()
    except rospy.ROSInterruptException:
        break
'''


def test_echo_formats_filters_by_level_and_name() -> None:
    Log = get_message_class("rosgraph_msgs/Log")
    echo = ConsoleEcho("^/no", "warn", nocolor=True)
    assert echo.text(Log(level=Log.WARN, name="/noisy", msg="careful")) == \
        "[ WARN  ] [\033[1m/noisy\033[21m]: careful"
    assert echo.text(Log(level=Log.INFO, name="/noisy", msg="hi")) is None
    assert echo.text(Log(level=Log.ERROR, name="/other", msg="x")) is None
    colored = ConsoleEcho(".*", "debug")
    assert colored.text(Log(level=Log.FATAL, name="/n", msg="x")).startswith("[ \033[95mFATAL\033[0m ]")


@pytest.fixture
def noisy(minros_core: int, ros_home: Path):
    env = ros_env(minros_core, ros_home)
    proc = Proc([PYTHON, "-c", NOISY], env)
    try:
        # its logger services are registered during init_node: wait for them
        master = xmlrpc.client.ServerProxy(f"http://127.0.0.1:{minros_core}/")
        wait_until(lambda: master.lookupService("/t", "/noisy/set_logger_level")[0] == 1, 30,
                   what="/noisy's logger services")
        yield env
    finally:
        proc.stop()


def _console(env: dict, *args: str, timeout: float = 30) -> subprocess.CompletedProcess:
    return subprocess.run([PYTHON, "-m", "minros", "console", *args], env=env,
                          capture_output=True, text=True, timeout=timeout)


def test_list_get_set_and_echo(noisy: dict) -> None:
    echo = _console(noisy, "echo", "-1", "--nocolor", "noisy", "warn")
    assert echo.returncode == 0, echo.stderr
    assert echo.stdout.splitlines() == ["[ WARN  ] [\033[1m/noisy\033[21m]: careful"]
    listed = _console(noisy, "list", "/noisy")
    assert listed.returncode == 0, listed.stderr
    assert "rosout" in listed.stdout.split()
    assert _console(noisy, "get", "/noisy", "rosout").stdout.strip() == "info"
    assert _console(noisy, "set", "/noisy", "rosout", "debug").returncode == 0
    assert _console(noisy, "get", "/noisy", "rosout").stdout.strip() == "debug"
    debug = _console(noisy, "echo", "-1", "--nocolor", ".*", "debug", "-v")
    assert debug.returncode == 0 and "]: " in debug.stdout
    missing = _console(noisy, "get", "/noisy", "nope")
    assert missing.returncode == 2
    assert missing.stderr.strip() == "rosconsole: error: node /noisy does not contain logger nope"
    bad = _console(noisy, "set", "/noisy", "rosout", "loud")
    assert bad.returncode == 2 and "rosconsole: error: invalid level" in bad.stderr


def test_usage_without_command(minros_core: int, ros_home: Path) -> None:
    out = _console(ros_env(minros_core, ros_home))
    assert out.returncode == 64
    assert out.stdout.startswith("rosconsole is a command-line tool")


CALLER = '''
import sys
import rospy
from rospy.logger_level_service_caller import LoggerLevelServiceCaller, ROSConsoleException
rospy.init_node("caller", anonymous=True, disable_rosout=True)
caller = LoggerLevelServiceCaller()
print("nodes", "/noisy" in caller.get_node_names())
print("loggers", "rosout" in caller.get_loggers("noisy"))
print("change", caller.send_logger_change_message("noisy", "rosout", "warn"))
print("again", caller.send_logger_change_message("noisy", "rosout", "warn"))
try:
    caller.get_loggers("/nobody")
except ROSConsoleException as exc:
    print("missing", "doesn't exist" in str(exc))
'''


def test_rospy_logger_level_service_caller_and_rosconsole_main(noisy: dict) -> None:
    out = subprocess.run([PYTHON, "-c", CALLER], env=noisy, capture_output=True, text=True,
                         timeout=60)
    assert out.returncode == 0, out.stderr
    assert out.stdout.split("\n")[:5] == ["nodes True", "loggers True", "change True",
                                          "again False", "missing True"]
    # rospy.rosconsole.main is the rosconsole command (program name first)
    get = subprocess.run([PYTHON, "-c", "from rospy.rosconsole import main; main(['rosconsole', "
                          "'get', '/noisy', 'rosout'])"], env=noisy, capture_output=True,
                         text=True, timeout=60)
    assert get.returncode == 0, get.stderr
    assert get.stdout.strip() == "warn"
    bad = subprocess.run([PYTHON, "-c", "from rospy.rosconsole import main; main(['rosconsole', "
                          "'get', '/noisy', 'nope'])"], env=noisy, capture_output=True,
                         text=True, timeout=60)
    assert bad.returncode == 2 and "does not contain logger nope" in bad.stderr


def test_roslaunch_logs_names_the_running_cores_log_folder(minros_core: int, ros_home: Path) -> None:
    env = ros_env(minros_core, ros_home)
    out = subprocess.run([PYTHON, "-c", "from roslaunch.roslaunch_logs import logs_main; logs_main()"],
                         env=env, capture_output=True, text=True, timeout=60)
    assert out.returncode == 0, out.stderr
    run_id = subprocess.run([PYTHON, "-m", "minros", "param", "get", "/run_id"], env=env,
                            capture_output=True, text=True, timeout=60).stdout.strip()
    assert run_id and out.stdout.strip().endswith("/" + run_id)
    assert Path(out.stdout.strip()).is_dir()  # the core logs there
