"""The node runtime in-process: a Node object of its own against an in-process master, with
fake publications and subscriptions, so registration, re-registration after a master restart
and shutdown are driven and observed directly (no subprocess)."""

from __future__ import annotations

import threading

import pytest

from minros.master import Master
from minros.node import Node
from minros.wire.xmlrpc import ServerProxy

TIMEOUT = 10.0


class FakePublication:
    type = "std_msgs/String"
    md5sum = "992ce8a1687cec8c8bd883ec73ca41d1"

    def __init__(self, name: str) -> None:
        self.resolved_name = name
        self.closed = threading.Event()

    def accept_subscriber(self, sock, addr, header):
        return "not in this test"

    def get_stats(self):
        return [self.resolved_name, 0, []]

    def get_stats_info(self):
        return []

    def close(self):
        self.closed.set()


class FakeSubscription:
    type = "std_msgs/String"

    def __init__(self, name: str) -> None:
        self.resolved_name = name
        self.updates: list = []
        self.updated = threading.Event()
        self.closed = threading.Event()

    def publisher_update(self, uris):
        self.updates.append(list(uris))
        self.updated.set()

    def get_stats(self):
        return [self.resolved_name, []]

    def get_stats_info(self):
        return []

    def close(self):
        self.closed.set()


@pytest.fixture
def master():
    m = Master(port=0, host="127.0.0.1", hostname="127.0.0.1").start()
    yield m
    m.stop()


def make_node(master: Master, name: str = "probe") -> Node:
    node = Node(argv=["prog", f"__master:={master.uri}", "__hostname:=127.0.0.1"])
    node.init(name, args_key=(name,))
    return node


def system_state(master: Master) -> dict:
    pubs, subs, srvs = master.handler.getSystemState("/test")[2]
    return {"pub": dict(pubs), "sub": dict(subs), "srv": dict(srvs)}


def test_node_registers_what_it_offers_and_asks_for(master):
    node = make_node(master)
    try:
        assert node.caller_id == "/probe" and node.initialized
        pub, sub = FakePublication("/chatter"), FakeSubscription("/chatter")
        node.add_publication(pub)
        node.add_subscription(sub)
        node.register_service("/probe/get", lambda sock, header: None)
        assert sub.updated.wait(TIMEOUT)
        assert sub.updates[-1] == [node.uri]  # the master told it about its own publisher
        state = system_state(master)
        assert state["pub"]["/chatter"] == ["/probe"]
        assert state["sub"]["/chatter"] == ["/probe"]
        assert state["srv"]["/probe/get"] == ["/probe"]
        assert master.handler.lookupNode("/test", "/probe")[2] == node.uri
    finally:
        node.signal_shutdown("test over")


def test_node_registers_again_after_the_master_restarted(master):
    node = make_node(master)
    port = master.port
    try:
        pub, sub = FakePublication("/scan"), FakeSubscription("/scan")
        node.add_publication(pub)
        node.add_subscription(sub)
        assert sub.updated.wait(TIMEOUT)
        master.stop()
        sub.updated.clear()
        again = Master(port=port, host="127.0.0.1", hostname="127.0.0.1")
        # a restarted master is another process: it answers getPid with another pid
        again.handler.getPid = lambda caller_id: [1, "", 424242]
        again.start()
        try:
            # the probe notices the new master (other pid or lost contact) and registers all
            assert sub.updated.wait(TIMEOUT), "no re-registration with the restarted master"
            state = system_state(again)
            assert state["pub"]["/scan"] == ["/probe"]
            assert state["sub"]["/scan"] == ["/probe"]
        finally:
            node.signal_shutdown("test over")
            again.stop()
    finally:
        node.signal_shutdown("test over")


def test_shutdown_runs_hooks_then_unregisters_and_closes(master):
    node = make_node(master)
    pub, sub = FakePublication("/out"), FakeSubscription("/in")
    node.add_publication(pub)
    node.add_subscription(sub)
    node.register_service("/probe/srv", lambda sock, header: None)
    order: list = []
    node.on_shutdown(lambda: order.append(("client", node.is_shutdown())))
    node.add_shutdown_hook(lambda reason: order.append(("internal", reason)))
    assert system_state(master)["pub"]["/out"] == ["/probe"]
    node.signal_shutdown("done")
    assert order == [("client", False), ("internal", "done")]
    assert node.is_shutdown() and pub.closed.is_set() and sub.closed.is_set()
    state = system_state(master)
    assert "/out" not in state["pub"] and "/in" not in state["sub"] and "/probe/srv" not in state["srv"]
    with pytest.raises(OSError):
        ServerProxy(node.uri, timeout=2.0).getPid("/test")  # the slave API is gone
    node.signal_shutdown("again")  # idempotent


def test_shutdown_during_a_registration_leaves_nothing_registered(master):
    """Ctrl-C while rospy.Subscriber(...) waits for the master: the registration in flight
    reaches the master first and the shutdown's unregistration after it, never the reverse
    (the master would keep a subscriber of a node that is gone)."""
    node = make_node(master)
    entered, release = threading.Event(), threading.Event()
    original = master.handler.registerSubscriber

    def slow_register(*args):
        entered.set()
        assert release.wait(TIMEOUT)
        return original(*args)

    master.handler.registerSubscriber = slow_register
    sub = FakeSubscription("/late")
    adding = threading.Thread(target=node.add_subscription, args=(sub,))
    adding.start()
    try:
        assert entered.wait(TIMEOUT)  # the registration is at the master, unanswered
        closing = threading.Thread(target=node.signal_shutdown, args=("ctrl-c",))
        closing.start()
        closing.join(0.3)
        assert closing.is_alive()  # the shutdown waits for the answer before unregistering
        release.set()
        closing.join(TIMEOUT)
        adding.join(TIMEOUT)
        assert not closing.is_alive() and not adding.is_alive()
        assert "/late" not in system_state(master)["sub"]
    finally:
        release.set()
        node.signal_shutdown("test over")


def test_remote_shutdown_answers_before_the_servers_close(master):
    node = make_node(master)
    try:
        proxy = ServerProxy(node.uri, timeout=5.0)
        assert proxy.shutdown("/tester", "bye") == [1, "shutdown", 0]
        assert node.wait_for_shutdown(TIMEOUT)
    finally:
        node.signal_shutdown("test over")


def test_init_twice_with_other_arguments_is_refused(master):
    node = make_node(master)
    try:
        assert node.init("probe", args_key=("probe",)) is False  # same arguments: nothing to do
        with pytest.raises(Exception, match="already been called with different arguments"):
            node.init("other", args_key=("other",))
    finally:
        node.signal_shutdown("test over")


def test_names_resolve_against_the_node_and_its_remappings(master):
    node = Node(argv=["prog", f"__master:={master.uri}", "__hostname:=127.0.0.1", "__ns:=/robot",
                      "scan:=/laser/scan"])
    node.init("driver", argv=["prog", f"__master:={master.uri}", "__hostname:=127.0.0.1",
                              "__ns:=/robot", "scan:=/laser/scan"], args_key=("driver",))
    try:
        assert node.caller_id == "/robot/driver"
        assert node.resolve_name("scan") == "/laser/scan"
        assert node.resolve_name("~status") == "/robot/driver/status"
        assert node.resolve_topic_name("odom") == "/robot/odom"
    finally:
        node.signal_shutdown("test over")
