"""The node's concerns one by one, in-process (minros/node/: names, lifecycle, registries); the
Node composing them with registration and servers is test_node_runtime.py."""

from __future__ import annotations

import threading
from typing import Any

import pytest

from minros.exceptions import ROSException, ROSInitException, ServiceException
from minros.node.connections import Connections
from minros.node.lifecycle import Lifecycle
from minros.node.names import NodeNames
from minros.node.registries import Registries


def test_names_before_and_after_the_node_is_named(monkeypatch):
    monkeypatch.delenv("ROS_MASTER_URI", raising=False)
    names = NodeNames(["prog", "__ns:=/robot", "scan:=/laser/scan", "__master:=http://m:1/"])
    assert names.caller_id == "/robot/unnamed" and not names.named
    assert names.resolve_topic_name("scan") == "/laser/scan"  # the namespace's rules, remapped
    with pytest.raises(ValueError, match="~name topics cannot be created before init_node"):
        names.resolve_topic_name("~private")
    assert names.master_uri == "http://m:1/"
    names.name_node("driver", ["prog", "__ns:=/robot", "scan:=/laser/scan"], argv_given=False,
                    anonymous=False)
    assert names.caller_id == "/robot/driver" and names.named
    assert names.resolve_topic_name("~status") == "/robot/driver/status"
    assert names.resolve_name("scan") == "/laser/scan"
    assert names.remap_name("scan") == "/laser/scan" and names.remap_name("other") == "other"
    assert names.get_namespace() == "/robot/"


def test_anonymous_and_renamed_nodes():
    names = NodeNames(["prog"])
    names.name_node("talker", ["prog"], argv_given=True, anonymous=True)
    assert names.caller_id.startswith("/talker_")
    names = NodeNames(["prog", "__name:=chosen"])
    names.name_node("talker", ["prog", "__name:=chosen"], argv_given=True, anonymous=True)
    assert names.caller_id == "/chosen"  # __name wins, and is not made anonymous


def test_lifecycle_runs_client_hooks_then_internal_hooks_then_close():
    order: list = []
    life = Lifecycle(close=lambda: order.append("close"))
    assert life.claim_init(("a",)) and not life.claim_init(("a",))
    with pytest.raises(ROSException, match="different arguments"):
        life.claim_init(("b",))
    life.on_shutdown(lambda: order.append(("client", life.is_shutdown())))
    life.add_shutdown_hook(lambda reason: order.append(("internal", reason)))
    with pytest.raises(TypeError):
        life.on_shutdown("not callable")
    life.signal_shutdown("done")
    assert order == [("client", False), ("internal", "done"), "close"]
    assert life.is_shutdown() and life.is_shutdown_requested() and life.wait_for_shutdown(0)
    life.on_shutdown(lambda: order.append("late"))  # after shutdown: runs at once
    life.signal_shutdown("again")
    assert order[-1] == "late" and order.count("close") == 1
    with pytest.raises(ROSInitException):
        Lifecycle(close=lambda: None).spin()  # before init_node


def test_a_second_shutdown_waits_for_the_first():
    entered, release = threading.Event(), threading.Event()
    life = Lifecycle(close=lambda: (entered.set(), release.wait(5)))
    first = threading.Thread(target=life.signal_shutdown, args=("first",))
    first.start()
    assert entered.wait(5)
    second = threading.Thread(target=life.signal_shutdown, args=("second",))
    second.start()
    second.join(0.2)
    assert second.is_alive()  # waits while the first is closing
    release.set()
    second.join(5)
    first.join(5)
    assert not second.is_alive() and not first.is_alive()


class Endpoint:
    type = "std_msgs/String"
    md5sum = "992ce8a1687cec8c8bd883ec73ca41d1"

    def __init__(self, name: str) -> None:
        self.resolved_name = name


def test_registries_own_what_the_node_offers_and_asks_for():
    reg = Registries()
    pub, other = Endpoint("/out"), Endpoint("/out")
    reg.add_publication(pub)
    assert not reg.remove_publication(other)  # not the registered one
    assert reg.publication_types() == {"/out": ("std_msgs/String", Endpoint.md5sum)}
    reg.add_subscription(Endpoint("/in"))
    reg.add_service("/srv", lambda stream, header, conn: None)
    with pytest.raises(ServiceException, match="already registered"):
        reg.add_service("/srv", lambda stream, header, conn: None)
    reg.add_param_subscription("/gains/")
    assert reg.snapshot() == ([("/out", "std_msgs/String")], [("/in", "std_msgs/String")],
                              ["/srv"], ["/gains/"])
    assert reg.remove_publication(pub) and reg.remove_service("/srv") and not reg.remove_service("/srv")


def test_param_updates_reach_the_handlers_and_the_subscribed_keys():
    reg = Registries()
    seen: list = []
    reg.add_param_update_handler(lambda key, value: seen.append((key, value)) or key == "/cached")
    reg.add_param_update_handler(lambda key, value: 1 / 0)  # a broken handler is logged only
    assert reg.param_update("/cached", 1)
    assert not reg.param_update("/elsewhere", 2)
    reg.add_param_subscription("/gains")
    assert reg.param_update("/gains/p", 3) and reg.param_update("/", {})
    assert seen[:2] == [("/cached", 1), ("/elsewhere", 2)]


def test_connections_route_inbound_headers_and_start_no_server_before_init(monkeypatch):
    monkeypatch.delenv("ROS_MASTER_URI", raising=False)
    names, reg = NodeNames(["prog"]), Registries()
    names.name_node("n", ["prog"], argv_given=True, anonymous=False)
    stopping = threading.Event()
    conns = Connections(names, reg, stopping.is_set, lambda: False)
    assert [h.protocol for h in conns.protocols][-1] == "TCPROS"  # TCPROS last
    with pytest.raises(ROSInitException, match="init_node"):
        conns.tcpros_address()
    assert conns.server is None  # not started by asking too early
    served: list = []
    reg.add_service("/srv", lambda stream, header, conn: served.append(header["service"]))
    assert conns.dispatch(None, {"service": "/srv", "callerid": "/c"}, None) is None
    assert served == ["/srv"]
    assert conns.dispatch(None, {"service": "/other", "callerid": "/c"}, None) == (
        "[/n] is not a provider of [/other]")
    assert "is not a publisher of [/t]" in conns.dispatch(
        None, {"topic": "/t", "md5sum": "*", "callerid": "/c"}, None)
    assert conns.dispatch(None, {"callerid": "/c"}, None) == "no topic or service name detected"
    stopping.set()
    assert conns.dispatch(None, {"topic": "/t", "md5sum": "*", "callerid": "/c"}, None) == (
        "Node is shutting down")
    assert conns.answer_protocol("/t", "TCPROS") is None  # not a list: not an offer
    assert conns.answer_protocol("/t", ["UDPROS"]) is None  # not spoken
    assert conns.local_transport("/t", object, {}) is None  # nothing published here


class _SlowMaster:
    """The few MasterClient calls Registration makes; register_service waits to be let go."""

    caller_id = "/n"
    uri = "http://m:1/"

    def __init__(self) -> None:
        self.entered, self.go, self.done = threading.Event(), threading.Event(), threading.Event()
        self.multicalls: list = []

    def register_service(self, service: str, rosrpc_uri: str, uri: str) -> None:
        self.entered.set()
        assert self.go.wait(5)
        self.done.set()

    def with_timeout(self, timeout: float) -> _SlowMaster:
        return self

    def multicall(self, calls: list) -> list:
        self.multicalls.append(calls)
        return []


class _LetsGoOnAcquire:
    """A lock that sets ``go`` when acquire() is called (close() waiting for it)."""

    def __init__(self, lock: Any, go: threading.Event) -> None:
        self._lock, self._go = lock, go

    def __enter__(self) -> Any:
        return self._lock.__enter__()

    def __exit__(self, *exc: Any) -> Any:
        return self._lock.__exit__(*exc)

    def acquire(self, timeout: float = -1) -> bool:
        self._go.set()
        return self._lock.acquire(timeout=timeout)

    def release(self) -> None:
        self._lock.release()


def test_shutdown_unregisters_a_service_whose_registration_was_in_flight():
    """A Ctrl-C while rospy registers its first service (the logger services at init): the
    services' URI is asked after that registration, so the multicall withdraws the service."""
    from minros.node.registration import Registration

    master, reg = _SlowMaster(), Registries()
    registration = Registration(master, reg, Lifecycle(lambda: None), lambda: "http://h:1/",
                                lambda: "rosrpc://h:2")
    registration.started = True
    # the registration in flight finishes once close() waits for the lock
    registration.lock = _LetsGoOnAcquire(registration.lock, master.go)  # type: ignore[assignment]
    reg.add_service("/n/get_loggers", lambda stream, header, conn: None)
    announcing = threading.Thread(target=registration.announce_service, args=("/n/get_loggers",))
    announcing.start()
    assert master.entered.wait(5)
    # the node serves a service once its registration is through (as close() asks the node)
    registration.unregister_all(lambda: "rosrpc://h:2" if master.done.is_set() else None)
    announcing.join(5)
    assert not announcing.is_alive()
    assert master.multicalls == [[
        {"methodName": "unregisterService", "params": ["/n", "/n/get_loggers", "rosrpc://h:2"]}]]
