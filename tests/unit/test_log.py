"""minros.client.log (console format, stdout/stderr split, levels, throttle/once/identical) and
minros.client.rosout_log (/rosout records, logger services)."""

from __future__ import annotations

import io
import logging
import re

import pytest

from minros import node
from minros.client import log, rosout_log, rostime


@pytest.fixture
def streams(monkeypatch):
    """The console handler writing into two StringIOs; rosout logger level restored after."""
    out, err = io.StringIO(), io.StringIO()
    handler = next(h for h in logging.getLogger("rosout").handlers if isinstance(h, log.ConsoleHandler))
    monkeypatch.setattr(handler, "_stdout", out)
    monkeypatch.setattr(handler, "_stderr", err)
    monkeypatch.delenv("ROSCONSOLE_FORMAT", raising=False)
    logger = logging.getLogger("rosout")
    saved = logger.level
    yield out, err
    logger.setLevel(saved)


@pytest.fixture
def fresh_throttles(monkeypatch):
    monkeypatch.setattr(log, "_throttle", log._Throttle())
    monkeypatch.setattr(log, "_identical", log._Identical())
    monkeypatch.setattr(log, "_once", log._Once())


LINE = re.compile(r"^\[(DEBUG|INFO|WARN|ERROR|FATAL)\] \[(\d+\.\d{6})(?:, (\d+\.\d{6}))?\]: (.*)$")


# ---------------------------------------------------------------------------- pure formatting

def test_default_format_is_rospys():
    line = log.format_console_line(log.DEFAULT_FORMAT, severity="INFO", message="hello world",
                                   wall_time=1600000000.123456)
    assert line == "[INFO] [1600000000.123456]: hello world"


def test_sim_time_is_appended_to_time():
    line = log.format_console_line(log.DEFAULT_FORMAT, severity="WARN", message="m",
                                   wall_time=1.5, ros_time=42.25)
    assert line == "[WARN] [1.500000, 42.250000]: m"


def test_all_rosconsole_tags():
    fmt = "${severity}|${message}|${walltime}|${node}|${logger}|${file}|${line}|${function}|${thread}|${time}"
    line = log.format_console_line(fmt, severity="ERROR", message="x", wall_time=2.0, node="/n",
                                   logger="rosout", file="/a/b.py", line=7, function="C.f", thread=9)
    assert line == "ERROR|x|2.000000|/n|rosout|/a/b.py|7|C.f|9|2.000000"


def test_strftime_tags(monkeypatch):
    monkeypatch.setattr(log.time, "strftime", lambda fmt: f"<{fmt}>")
    line = log.format_console_line("${time:%H:%M} ${walltime:%Y} ${message}", severity="INFO",
                                   message="m", wall_time=0.0, ros_time=3.0)
    assert line == "<%H:%M>, 3.000000 <%Y> m"
    # an unterminated tag is left alone instead of looping forever
    assert log.format_console_line("${time:%H", severity="I", message="", wall_time=0) == "${time:%H"


# ---------------------------------------------------------------------------- console

def test_info_to_stdout_warn_and_worse_to_stderr(streams):
    out, err = streams
    log.loginfo("hello %s", "world")
    log.logwarn("careful")
    log.logerr("broken")
    log.logfatal("dead")
    out_lines = out.getvalue().splitlines()
    err_lines = err.getvalue().splitlines()
    assert len(out_lines) == 1
    m = LINE.match(out_lines[0])
    assert m and m.group(1) == "INFO" and m.group(4) == "hello world"
    assert [LINE.match(x).group(1) for x in err_lines] == ["WARN", "ERROR", "FATAL"]
    assert LINE.match(err_lines[0]).group(4) == "careful"


def test_debug_hidden_at_default_level_shown_at_debug(streams):
    out, _ = streams
    log.logdebug("not shown")
    assert out.getvalue() == ""
    logging.getLogger("rosout").setLevel(logging.DEBUG)
    log.logdebug("shown")
    assert LINE.match(out.getvalue().strip()).group(1) == "DEBUG"


def test_log_level_filter_error_hides_warn(streams):
    _, err = streams
    logging.getLogger("rosout").setLevel(log.ROS_TO_LOGGING[log.ERROR])
    log.logwarn("hidden")
    log.logerr("visible")
    assert "hidden" not in err.getvalue() and "visible" in err.getvalue()


def test_rosconsole_format_env(streams, monkeypatch):
    out, _ = streams
    monkeypatch.setenv("ROSCONSOLE_FORMAT", "${severity} ${logger} ${function}: ${message}")

    class Greeter:
        def greet(self):
            log.loginfo("hi", logger_name="greeter")

    Greeter().greet()
    assert out.getvalue() == "INFO rosout.greeter Greeter.greet: hi\n"


def test_python_logging_rosout_logger_reaches_console(streams):
    out, err = streams
    logging.getLogger("rosout").info("plain logging %d", 5)
    logging.getLogger("rosout.sub").warning("child")
    assert LINE.match(out.getvalue().strip()).group(4) == "plain logging 5"
    assert LINE.match(err.getvalue().strip()).group(4) == "child"


def test_logout_and_logerror_aliases():
    assert log.logout is log.loginfo
    assert log.logerror is log.logerr
    assert (log.DEBUG, log.INFO, log.WARN, log.ERROR, log.FATAL) == (1, 2, 4, 8, 16)


# ---------------------------------------------------------------------------- throttle / once

def test_once_logs_first_call_of_each_call_site(streams, fresh_throttles):
    out, _ = streams
    for i in range(3):
        log.loginfo_once(f"first {i}")
    log.loginfo_once("another site")
    assert [LINE.match(x).group(4) for x in out.getvalue().splitlines()] == ["first 0", "another site"]


def test_throttle_uses_ros_time(streams, fresh_throttles):
    out, _ = streams
    saved = (rostime._clock.initialized, rostime._clock.sim_time)
    rostime._set_initialized(True)
    try:
        for t in (100.0, 100.5, 100.99, 101.01, 101.5, 102.2):
            rostime._set_rostime(rostime.Time.from_sec(t))
            log.loginfo_throttle(1.0, f"tick {t}")
    finally:
        rostime._clock.initialized, rostime._clock.sim_time = saved
    matches = [LINE.match(x) for x in out.getvalue().splitlines()]
    assert [m.group(4) for m in matches] == ["tick 100.0", "tick 101.01", "tick 102.2"]
    # on simulated time the console shows the ROS time after the wall time
    assert [m.group(3) for m in matches] == ["100.000000", "101.010000", "102.200000"]
    # time jumping backwards forgets the throttle state (rospy's rule)
    thr = log._Throttle()
    key = ("f", 1, 2)
    assert thr(key, 1.0, now=10.0) and not thr(key, 1.0, now=10.5) and thr(key, 1.0, now=5.0)


def test_throttle_identical_logs_changes_and_periodic_repeats(streams, fresh_throttles):
    out, _ = streams
    saved = (rostime._clock.initialized, rostime._clock.sim_time)
    rostime._set_initialized(True)
    try:
        for t, text in ((10.0, "a"), (10.1, "a"), (10.2, "b"), (10.3, "b"), (11.5, "b")):
            rostime._set_rostime(rostime.Time.from_sec(t))
            log.logwarn_throttle_identical(1.0, text)
    finally:
        rostime._clock.initialized, rostime._clock.sim_time = saved
    lines = [LINE.match(x).group(4) for x in streams[1].getvalue().splitlines()]
    assert lines == ["a", "b", "b"]


def test_throttle_before_init_uses_wall_clock(streams, fresh_throttles):
    out, _ = streams
    saved = rostime._clock.initialized
    rostime._set_initialized(False)
    try:
        for _ in range(3):
            log.loginfo_throttle(60, "once a minute")
    finally:
        rostime._set_initialized(saved)
    assert out.getvalue().count("once a minute") == 1


# ---------------------------------------------------------------------------- /rosout records

class FakePublisher:
    def __init__(self):
        self.sent = []

    def publish(self, msg):
        self.sent.append(msg)
        log.loginfo("logging from inside publish must not recurse")


def test_rosout_handler_publishes_log_messages(streams, monkeypatch):
    from rosgraph_msgs.msg import Log

    pub = FakePublisher()
    monkeypatch.setattr(rosout_log._rosout, "publisher", pub)
    monkeypatch.setattr(rosout_log, "_get_param_cached", lambda key, default: default)
    monkeypatch.setattr(rosout_log, "_node_topics", lambda: ["/chatter", "/rosout"])
    handler = rosout_log.RosoutHandler()
    logger = logging.getLogger("rosout")
    logger.addHandler(handler)
    try:
        class Talker:
            def talk(self):
                log.logwarn("speed %d", 3)

        Talker().talk()
        expected_line = Talker.talk.__code__.co_firstlineno + 1
        logging.getLogger("rosout").error("from python logging")
    finally:
        logger.removeHandler(handler)
    assert len(pub.sent) == 2
    first = pub.sent[0]
    assert isinstance(first, Log)
    assert first.level == Log.WARN == 4
    assert first.msg == "speed 3"
    assert first.file == "test_log.py"
    assert first.function == "Talker.talk"
    assert first.line == expected_line
    assert first.topics == ["/chatter", "/rosout"]
    assert first.name == node.get_caller_id()
    assert not first.header.stamp.is_zero()
    assert pub.sent[1].level == Log.ERROR and pub.sent[1].msg == "from python logging"


def test_logger_services_handlers():
    from roscpp.srv import GetLoggersRequest, SetLoggerLevelRequest

    logging.getLogger("minros.test.svc").setLevel(logging.ERROR)
    response = rosout_log._get_loggers(GetLoggersRequest())
    levels = {lg.name: lg.level for lg in response.loggers}
    assert levels["minros.test.svc"] == "error"
    rosout_log._set_logger_level(SetLoggerLevelRequest(logger="minros.test.svc", level="debug"))
    assert logging.getLogger("minros.test.svc").level == logging.DEBUG
    response = rosout_log._get_loggers(GetLoggersRequest())
    assert {lg.name: lg.level for lg in response.loggers}["minros.test.svc"] == "debug"


def test_node_log_filename_rules(tmp_path):
    env = {"ROS_LOG_DIR": "/logs", "ROS_HOME": "/home"}
    assert log.node_log_filename("/talker", {}, env) == "/logs/talker.log"
    assert log.node_log_filename("/ns/sub/talker", {}, env) == "/logs/ns_sub_talker.log"
    assert log.node_log_filename("/talker", {}, {"ROS_HOME": "/home"}) == "/home/log/talker.log"
    assert log.node_log_filename("/t", {"__log": str(tmp_path / "x.log")}, env) == str(tmp_path / "x.log")


def test_failed_param_lookup_is_not_retried_on_every_record(monkeypatch):
    from minros.client import params

    calls = []

    def failing(key, default):
        calls.append(key)
        raise OSError("master unreachable")

    monkeypatch.setattr(params, "get_param_cached", failing)
    monkeypatch.setattr(rosout_log, "_param_failed_at", {})
    assert rosout_log._get_param_cached("/rosout_disable_topics_generation", False) is False
    assert rosout_log._get_param_cached("/rosout_disable_topics_generation", False) is False
    assert calls == ["/rosout_disable_topics_generation"]
    rosout_log._param_failed_at["/rosout_disable_topics_generation"] -= rosout_log._PARAM_RETRY + 1
    rosout_log._get_param_cached("/rosout_disable_topics_generation", False)
    assert len(calls) == 2
