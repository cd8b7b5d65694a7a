"""rosgraph.xmlrpc, rosgraph.roslogging and rosgraph.network's header functions."""

from __future__ import annotations

import io
import logging
import struct
import subprocess
import sys
import threading
import xmlrpc.client
from pathlib import Path

import pytest

import rosgraph.network
import rosgraph.rosenv
import rosgraph.roslogging
import rosgraph.xmlrpc


class Echo(rosgraph.xmlrpc.XmlRpcHandler):
    def __init__(self) -> None:
        self.ready = threading.Event()
        self.uri = None
        self.reason = None

    def _ready(self, uri: str) -> None:
        self.uri = uri
        self.ready.set()

    def _shutdown(self, reason: str) -> None:
        self.reason = reason

    def echo(self, value):
        return [1, "ok", value]


def test_xmlrpc_node_serves_its_handler_and_reports_its_life(monkeypatch):
    monkeypatch.setenv("ROS_HOSTNAME", "localhost")
    handler = Echo()
    node = rosgraph.xmlrpc.XmlRpcNode(0, handler)
    node.start()
    assert handler.ready.wait(10)
    assert handler.uri == node.uri == f"http://localhost:{node.port}/"
    proxy = xmlrpc.client.ServerProxy(node.uri)
    assert proxy.echo({"a": [1, 2]}) == [1, "ok", {"a": [1, 2]}]
    multi = xmlrpc.client.MultiCall(proxy)
    multi.echo(1)
    multi.echo(2)
    assert [r[2] for r in multi()] == [1, 2]
    node.shutdown("test over")
    assert handler.reason == "test over" and node.uri is None and node.is_shutdown


def test_xmlrpc_node_port_in_use_is_one_clear_error(monkeypatch, capsys):
    monkeypatch.setenv("ROS_HOSTNAME", "localhost")
    first = rosgraph.xmlrpc.XmlRpcNode(0, Echo())
    first._run_init()
    errors = []
    second = rosgraph.xmlrpc.XmlRpcNode(first.port, Echo(), on_run_error=errors.append)
    second.run()
    first.shutdown("done")
    assert len(errors) == 1 and isinstance(errors[0], OSError)
    assert f"port {second.port} is already in use" in capsys.readouterr().out


def test_handshake_header_functions_accept_bytes_and_strip_keys():
    encoded = rosgraph.network.encode_ros_handshake_header({b"b": b"2", "a": "1"})
    assert encoded == rosgraph.network.encode_ros_handshake_header({"a": "1", "b": "2"})
    field = b" topic =/x"
    block = struct.pack("<I", len(field)) + field
    assert rosgraph.network.decode_ros_handshake_header(struct.pack("<I", len(block)) + block) == {"topic": "/x"}
    with pytest.raises(rosgraph.network.ROSHandshakeException):
        rosgraph.network.decode_ros_handshake_header(struct.pack("<I", 50) + block)


def test_bad_master_remapping_is_a_value_error():
    assert rosgraph.rosenv.get_master_uri(env={}, argv=["__master:=http://h:1/", "__master:=x"]) == "http://h:1/"
    for bad in ("__master:=", "__master:=a:=b"):
        with pytest.raises(ValueError, match="improperly specified"):
            rosgraph.rosenv.get_master_uri(argv=[bad])


def test_configure_logging_uses_ros_config_and_names_methods(tmp_path: Path, monkeypatch):
    monkeypatch.setenv("ROS_LOG_DIR", str(tmp_path / "log"))
    monkeypatch.setenv("ROS_HOME", str(tmp_path))
    monkeypatch.delenv("ROS_PYTHON_LOG_CONFIG_FILE", raising=False)
    monkeypatch.setenv("ROS_ETC_DIR", str(tmp_path / "etc"))
    monkeypatch.setenv("ROSCONSOLE_FORMAT", "${severity} ${function} ${message}")
    root_handlers = list(logging.getLogger().handlers)
    rosout = logging.getLogger("rosout")
    rosout_handlers = list(rosout.handlers)
    try:
        path = rosgraph.roslogging.configure_logging("probe", filename="run1/probe.log")
        assert path == str(tmp_path / "log" / "run1" / "probe.log")
        assert (tmp_path / "log" / "latest").resolve() == tmp_path / "log" / "run1"
        handler = rosout.handlers[0]
        assert isinstance(handler, rosgraph.roslogging.RosStreamHandler)
        out, err = io.StringIO(), io.StringIO()
        rosout.removeHandler(handler)
        rosout.addHandler(rosgraph.roslogging.RosStreamHandler(False, out, err))

        class Probe:
            def speak(self):
                logging.getLogger("rosout").warning("careful")

        Probe().speak()
        assert err.getvalue() == "WARN Probe.speak careful\n" and out.getvalue() == ""
        for h in logging.getLogger().handlers:
            h.flush()
        assert "[rosout][WARNING]" in Path(path).read_text()
    finally:
        for h in logging.getLogger().handlers:
            if h not in root_handlers:
                logging.getLogger().removeHandler(h)
                h.close()
        rosout.handlers[:] = rosout_handlers


def test_configure_logging_refuses_a_file_in_the_way(tmp_path: Path, monkeypatch):
    monkeypatch.setenv("ROS_LOG_DIR", str(tmp_path))
    (tmp_path / "blocker").write_text("x")
    with pytest.raises(rosgraph.roslogging.LoggingException, match="is in the way"):
        rosgraph.roslogging.configure_logging("x", filename="blocker/x.log")


@pytest.mark.slow
def test_rosout_logger_made_before_roslogging_names_methods_too():
    """minros's node names the 'rosout' logger on import, possibly before roslogging's is
    imported: that logger still names a method's caller Class.method."""
    code = (
        "import logging; early = logging.getLogger('rosout'); other = logging.getLogger('app')\n"
        "import minros.roslogging as r\n"
        "assert type(early) is r.RospyLogger and type(other) is logging.Logger\n"
    )
    subprocess.run([sys.executable, "-c", code], check=True, timeout=60)
