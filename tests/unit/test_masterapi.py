"""The one master client (wire/masterapi.py) against an in-process master: typed results, one
error path (MasterError for -1, MasterFailure for 0 and faults, MasterIOError for the network),
and the faces built on it (rosgraph.Master for the tools, rospy's MasterProxy)."""

from __future__ import annotations

import threading

import pytest

from minros.master import Master
from minros.tools.master import Master as ToolMaster
from minros.wire import rosapi
from minros.wire.masterapi import (
    MasterClient,
    MasterError,
    MasterFailure,
    MasterIOError,
    RemoteError,
    SystemState,
)
from support import free_port


@pytest.fixture
def master():
    m = Master(port=0, host="127.0.0.1", hostname="127.0.0.1").start()
    yield m
    m.stop()


def test_typed_calls_and_results(master):
    client = MasterClient(master.uri, "/probe")
    assert client.register_subscriber("/chatter", "std_msgs/String", "http://h:1/") == []
    assert client.register_publisher("/chatter", "std_msgs/String", "http://h:1/") == ["http://h:1/"]
    client.register_service("/probe/srv", "rosrpc://h:2", "http://h:1/")
    assert client.lookup_service("/probe/srv") == "rosrpc://h:2"
    assert client.lookup_node("/probe") == "http://h:1/"
    assert client.get_published_topics("/") == [("/chatter", "std_msgs/String")]
    state = client.get_system_state()
    assert isinstance(state, SystemState)
    assert state.publishers == [["/chatter", ["/probe"]]] and state.services == [["/probe/srv", ["/probe"]]]
    client.set_param("/a/b", 3)
    assert client.get_param("/a") == {"b": 3} and client.has_param("/a/b")
    assert client.search_param("b") is None and client.get_param_names() == ["/a/b"]
    assert client.unregister_publisher("/chatter", "http://h:1/") == 1
    assert isinstance(client.get_pid(), int)
    assert client.raw("getParam", "/nope")[0] == rosapi.ERROR  # rospy's MasterProxy reads triplets


def test_one_error_path(master):
    client = MasterClient(master.uri, "/probe")
    with pytest.raises(MasterError, match=r"Parameter \[/nope\] is not set") as unset:
        client.get_param("/nope")
    assert unset.value.code == -1 and isinstance(unset.value, RemoteError)
    with pytest.raises(MasterFailure, match="noSuchMethod"):
        client.call("noSuchMethod")  # a fault: the master could not do it
    with pytest.raises(MasterIOError) as down:
        MasterClient(f"http://127.0.0.1:{free_port()}/", "/probe", timeout=2.0).get_pid()
    assert isinstance(down.value, OSError)
    with pytest.raises(MasterIOError, match="invalid ROS_MASTER_URI"):
        MasterClient("localhost:11311", "/probe").get_pid()


def test_names_are_read_per_call_and_each_thread_has_its_connection(master):
    names = {"caller": "/unnamed"}
    client = MasterClient(lambda: master.uri, lambda: names["caller"])
    client.register_publisher("/t", "std_msgs/String", "http://h:1/")
    names["caller"] = "/named"  # init_node renamed the node
    client.register_publisher("/u", "std_msgs/String", "http://h:2/")
    pubs = dict(client.get_system_state().publishers)
    assert pubs == {"/t": ["/unnamed"], "/u": ["/named"]}
    proxies = []
    thread = threading.Thread(target=lambda: proxies.append((client.get_pid(), client._proxy())))
    thread.start()
    thread.join(10)
    client.get_pid()
    assert proxies and proxies[0][1] is not client._proxy()


def test_rosgraph_face_for_the_tools(master):
    tool = ToolMaster("rostopic", master.uri)  # a relative caller id goes in the namespace
    assert tool.caller_id == "/rostopic" and tool.is_online()
    tool.setParam("/x", 1)  # rosgraph's camelCase calls, unwrapped
    assert tool.getParam("/x") == 1
    with pytest.raises(MasterError):
        tool.getParam("/y")
    assert tool.topic_types() == [] and tool.system_state() == ([], [], [])
    assert not ToolMaster("/t", f"http://127.0.0.1:{free_port()}/", timeout=1.0).is_online()
