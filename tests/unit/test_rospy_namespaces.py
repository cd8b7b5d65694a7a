"""rospy's modules star-import rospy.core (``from rospy.core import *``), so code reaches the
core's names through rospy.topics, rospy.service, rospy.impl.*: the same objects are there, and
the helpers those modules define (QueuedConnection, LoggingThrottle, ...) do their work."""

from __future__ import annotations

import sys
import threading
import time
from xmlrpc.server import SimpleXMLRPCServer

import pytest

import rospy.client
import rospy.core
import rospy.impl.masterslave
import rospy.impl.registration
import rospy.impl.rosout
import rospy.impl.tcpros_base
import rospy.impl.tcpros_pubsub
import rospy.names
import rospy.service
import rospy.topics
from rospy.impl.transport import OUTBOUND, Transport


@pytest.mark.parametrize("module", [rospy.topics, rospy.service, rospy.impl.tcpros_base,
                                    rospy.impl.masterslave])
def test_star_import_of_rospy_core(module):
    for name in rospy.core.__all__:
        assert getattr(module, name) is getattr(rospy.core, name), name


def test_from_rospy_core_import_star_gives_rospys_names():
    scope: dict = {}
    exec("from rospy.core import *", scope)
    assert scope["Log"]._type == "rosgraph_msgs/Log"
    assert scope["resolve_name"] is rospy.names.resolve_name
    assert scope["make_global_ns"]("foo") == "/foo/"
    assert "threading" not in scope and "Any" not in scope  # only rospy's names


@pytest.mark.slow
def test_log_class_is_built_on_first_use_only():
    code = ("import sys, rospy, rospy.topics, rospy.service; "
            "assert not any(m.endswith('_Log') for m in sys.modules), 'built at import'; "
            "assert rospy.topics.Log._type == 'rosgraph_msgs/Log'")
    import subprocess
    subprocess.run([sys.executable, "-c", code], check=True, timeout=60)


def test_client_exposes_the_logger_messages_and_levels():
    assert rospy.client.GetLoggersResponse is rospy.client.GetLoggers._response_class
    assert rospy.client.Logger._type == "roscpp/Logger"
    assert (rospy.client.DEBUG, rospy.client.FATAL) == (rospy.client.Log.DEBUG, rospy.client.Log.FATAL)
    assert rospy.client.get_param is rospy.get_param
    with pytest.raises(AttributeError):
        rospy.client.NoSuchName  # noqa: B018


def test_logging_throttle_identical_once():
    throttle = rospy.core.LoggingThrottle()
    assert throttle("a", 10.0) and not throttle("a", 10.0) and throttle("b", 10.0)
    assert throttle("c", 0.0)
    time.sleep(0.01)
    assert throttle("c", 0.0)
    identical = rospy.core.LoggingIdentical()
    assert identical("a", "x") and not identical("a", "x") and identical("a", "y")
    once = rospy.core.LoggingOnce()
    assert once(1) and not once(1) and once(2)


def test_names_and_helpers_rospys_modules_import():
    assert rospy.names.isstring("x") and not rospy.names.isstring(b"x")
    assert rospy.names.GLOBALNS == "/" and rospy.names.REMAP == ":="
    assert rospy.impl.masterslave.STATUS == 0 and rospy.impl.masterslave.VAL == 2
    assert rospy.impl.registration.get_caller_id is rospy.names.get_caller_id
    assert rospy.impl.rosout.Log is rospy.core.Log
    with pytest.raises(AttributeError):
        rospy.impl.rosout.Nothing  # noqa: B018


class _Recorder(Transport):
    transport_type = "TEST"

    def __init__(self, fail_on: bytes = b"") -> None:
        super().__init__(OUTBOUND, "recorder")
        self.written: list = []
        self.fail_on = fail_on
        self.arrived = threading.Event()

    def write_data(self, data: bytes) -> bool:
        if data == self.fail_on:
            raise OSError("peer gone")
        self.written.append(data)
        self.arrived.set()
        return True


def test_queued_connection_relays_in_order_and_reports_errors():
    wrapped = _Recorder(fail_on=b"bad")
    queued = rospy.topics.QueuedConnection(wrapped, 0)
    try:
        assert queued.name == "recorder"  # other attributes are the wrapped transport's
        for i in range(50):
            queued.write_data(b"%d" % i)
        deadline = time.monotonic() + 5
        while len(wrapped.written) < 50 and time.monotonic() < deadline:
            wrapped.arrived.wait(0.1)
            wrapped.arrived.clear()
        assert wrapped.written == [b"%d" % i for i in range(50)]
        queued.write_data(b"bad")
        deadline = time.monotonic() + 5
        while queued._error is None and time.monotonic() < deadline:
            time.sleep(0.01)
        with pytest.raises(OSError, match="peer gone"):
            queued.write_data(b"next")
    finally:
        wrapped.close()  # the cleanup callback wakes the relay thread, which ends
        queued._thread.join(5)
    assert not queued._thread.is_alive()


def test_queued_connection_drops_the_oldest_beyond_its_size():
    wrapped = _Recorder()
    gate = threading.Lock()
    gate.acquire()
    original = wrapped.write_data

    def slow(data: bytes) -> bool:
        with gate:
            return original(data)

    wrapped.write_data = slow  # type: ignore[method-assign]
    queued = rospy.impl.tcpros_pubsub.QueuedConnection(wrapped, 2)
    try:
        queued.write_data(b"0")  # taken by the relay thread, which then blocks on the gate
        deadline = time.monotonic() + 5
        while queued._queue and time.monotonic() < deadline:
            time.sleep(0.01)
        for data in (b"1", b"2", b"3"):
            queued.write_data(data)
        assert queued._queue == [b"2", b"3"]
    finally:
        gate.release()
        deadline = time.monotonic() + 5
        while len(wrapped.written) < 3 and time.monotonic() < deadline:
            time.sleep(0.01)
        wrapped.close()
        queued._thread.join(5)
    assert wrapped.written == [b"0", b"2", b"3"]


def test_check_if_still_publisher_asks_the_node():
    server = SimpleXMLRPCServer(("127.0.0.1", 0), logRequests=False)
    server.register_function(lambda caller: [1, "", [["/chatter", "std_msgs/String"]]],
                             "getPublications")
    thread = threading.Thread(target=server.serve_forever, daemon=True)
    thread.start()
    uri = f"http://127.0.0.1:{server.server_address[1]}/"
    try:
        check = rospy.impl.tcpros_pubsub.check_if_still_publisher
        assert check("/chatter", uri)
        assert not check("/other", uri)
    finally:
        server.shutdown()
        server.server_close()
    assert not check("/chatter", uri)  # nobody answers any more
