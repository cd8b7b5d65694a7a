"""The one node-API client (wire/slaveapi.py) against a node of this process and an in-process
master: typed results, one error path (NodeError for -1, NodeFailure for 0, faults and
malformed answers, OSError of its own class for the network), and no raw callers left."""

from __future__ import annotations

import re
from pathlib import Path

import pytest

from minros.master import Master
from minros.node import Node
from minros.wire.slaveapi import NodeError, NodeFailure, RemoteError, SlaveClient
from support import free_port

SRC = Path(__file__).resolve().parents[2] / "src" / "minros"


@pytest.fixture
def node():
    master = Master(port=0, host="127.0.0.1", hostname="127.0.0.1").start()
    node = Node(argv=["prog", f"__master:={master.uri}", "__hostname:=127.0.0.1"])
    node.init("slave_probe", args_key=("slave_probe",))
    yield node
    node.signal_shutdown("test over")
    master.stop()


def test_typed_calls_and_results(node):
    import os

    with SlaveClient(node.uri, "/probe") as client:
        assert client.get_pid() == os.getpid()
        assert client.get_name() == "/slave_probe" and client.get_uri() == node.uri
        assert client.get_master_uri() == node.master_uri
        assert client.get_bus_info() == [] and client.get_bus_stats() == [[], [], []]
        assert client.get_subscriptions() == [] and client.get_publications() == []
        client.publisher_update("/nobody", [])  # a topic it does not subscribe to: fine


def test_one_error_path(node):
    client = SlaveClient(node.uri, "/probe")
    with pytest.raises(NodeError, match=r"Not a publisher of \[/chatter\]") as refused:
        client.request_topic("/chatter", [["TCPROS"]])
    assert refused.value.code == -1 and isinstance(refused.value, RemoteError)
    with pytest.raises(NodeError, match="not subscribed"):
        client.param_update("/p", 1)
    with pytest.raises(NodeFailure, match="noSuchMethod"):
        client.call("noSuchMethod")  # a fault
    client.close()
    with pytest.raises(ConnectionRefusedError):  # the network error keeps its class
        SlaveClient(f"http://127.0.0.1:{free_port()}/", "/probe", timeout=2.0).get_pid()
    with pytest.raises(OSError, match="not a node's XML-RPC URI"):
        SlaveClient("rosrpc://h:1", "/probe").get_pid()


def test_malformed_answers_are_node_failures(monkeypatch):
    client = SlaveClient("http://127.0.0.1:1/", "/probe")
    answers = iter([[1, "", "x"], [1, "", [[1, 2]]], [1, "", True], [1, "", []], "junk"])
    monkeypatch.setattr(client, "raw", lambda method, *args: next(answers))
    with pytest.raises(NodeFailure, match="malformed"):
        client.get_bus_info()  # not rows
    with pytest.raises(NodeFailure, match="malformed"):
        client.get_bus_info()  # rows too short
    with pytest.raises(NodeFailure, match="malformed getPid"):
        client.get_pid()
    with pytest.raises(NodeFailure, match="invalid protocol choice"):
        client.request_topic("/t", [["TCPROS"]])
    with pytest.raises(NodeFailure, match="malformed ROS API result"):
        client.get_name()


def test_no_raw_node_api_callers_are_left():
    """One requestTopic caller (the client itself) and no call_node(uri, "method") strings:
    every call to a node (the master's callbacks, the tools, minros web) is SlaveClient's."""
    pattern = re.compile(r'requestTopic\(|(call|raw)\("requestTopic"|call_node\(')
    found = [f"{path.relative_to(SRC)}:{n}: {line}"
             for path in sorted(SRC.rglob("*.py"))
             for n, line in enumerate(path.read_text().splitlines(), 1) if pattern.search(line)]
    callers = [line for line in found if "requestTopic" in line and "def requestTopic" not in line]
    assert len(callers) == 1 and "wire/slaveapi.py" in callers[0], callers
    strings = [line for line in found if re.search(r'call_node\([^,]+, "', line)]
    assert strings == [], strings
