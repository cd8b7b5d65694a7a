"""Conformance: the same XML-RPC calls against Debian's rosmaster and minros's master.

Each scenario runs on both masters (fresh ones per test) and the normalised results must be
identical: codes, status messages, values, faults, and the callbacks the masters make to nodes.
The per-master robustness tests (hostile clients) are parametrized over the two masters.
"""

from __future__ import annotations

import socket
import threading
import time
import xmlrpc.client
from typing import Any, Callable, Dict, List

import pytest

from minros.wire.xmlrpc import XmlRpcServer
from support import free_port, require_reference

pytestmark = pytest.mark.interop


# ---------------------------------------------------------------- machinery


class Recorder:
    """A fake node: records every slave-API callback the master makes."""

    def __init__(self) -> None:
        self.calls: List[tuple] = []
        self.cond = threading.Condition()

    def _record(self, method: str, *args: Any) -> List[Any]:
        with self.cond:
            self.calls.append((method, *args))
            self.cond.notify_all()
        return [1, "", 0]

    def publisherUpdate(self, *args):
        return self._record("publisherUpdate", *args)

    def paramUpdate(self, *args):
        return self._record("paramUpdate", *args)

    def shutdown(self, *args):
        return self._record("shutdown", *args)

    def wait_for(self, count: int, timeout: float = 5.0) -> List[tuple]:
        deadline = time.monotonic() + timeout
        with self.cond:
            while len(self.calls) < count and time.monotonic() < deadline:
                self.cond.wait(deadline - time.monotonic())
            return list(self.calls)


class FakeNodes:
    def __init__(self, subst: Dict[str, str]) -> None:
        self.servers: List[XmlRpcServer] = []
        self.subst = subst

    def new(self) -> tuple:
        rec = Recorder()
        srv = XmlRpcServer(rec, "127.0.0.1").start()
        self.servers.append(srv)
        self.subst[f"127.0.0.1:{srv.port}/"] = f"fake{len(self.servers)}/"
        return f"http://127.0.0.1:{srv.port}/", rec

    def dead(self) -> str:
        """A URI nobody listens on: callbacks to it fail at once."""
        port = free_port()
        self.subst[f"127.0.0.1:{port}/"] = "dead/"
        return f"http://127.0.0.1:{port}/"

    def close(self) -> None:
        for srv in self.servers:
            srv.shutdown()


class Client:
    """Calls one master; results are normalised so the two masters can be compared."""

    def __init__(self, port: int, subst: Dict[str, str]) -> None:
        self.port = port
        self.proxy = xmlrpc.client.ServerProxy(f"http://127.0.0.1:{port}/")
        self.subst = subst

    def norm(self, value: Any) -> Any:
        if isinstance(value, str):
            for old, new in self.subst.items():
                value = value.replace(old, new)
            return value
        if isinstance(value, (list, tuple)):
            return [self.norm(v) for v in value]
        if isinstance(value, dict):
            return {k: self.norm(v) for k, v in value.items()}
        return value

    def __call__(self, method: str, *args: Any) -> Any:
        try:
            return self.norm(getattr(self.proxy, method)(*args))
        except xmlrpc.client.Fault as fault:
            return ["FAULT", fault.faultCode, self.norm(fault.faultString)]

    def raw(self, body: bytes) -> Any:
        with socket.create_connection(("127.0.0.1", self.port), timeout=10) as s:
            s.sendall(b"POST / HTTP/1.1\r\nHost: x\r\nContent-Type: text/xml\r\nContent-Length: "
                      + str(len(body)).encode() + b"\r\nConnection: close\r\n\r\n" + body)
            data = b""
            while True:
                chunk = s.recv(65536)
                if not chunk:
                    break
                data += chunk
        head, _, payload = data.partition(b"\r\n\r\n")
        status = head.split(b" ")[1].decode()
        if status != "200":
            return ["HTTP", status]
        try:
            return self.norm(xmlrpc.client.loads(payload)[0][0])
        except xmlrpc.client.Fault as fault:
            return ["FAULT", fault.faultCode, self.norm(fault.faultString)]


Scenario = Callable[[Client, FakeNodes], List[Any]]


@pytest.fixture
def both(debian_rosmaster, minros_master):
    require_reference()
    return {"debian": debian_rosmaster, "minros": minros_master}


def run_both(both: Dict[str, int], scenario: Scenario) -> None:
    results = {}
    for kind, port in both.items():
        subst = {str(port): "PORT"}
        fakes = FakeNodes(subst)
        try:
            results[kind] = scenario(Client(port, subst), fakes)
        finally:
            fakes.close()
    deb, ours = results["debian"], results["minros"]
    diffs = [(i, d, o) for i, (d, o) in enumerate(zip(deb, ours)) if d != o]
    assert not diffs, "\n".join(f"step {i}:\n  debian: {d!r}\n  minros: {o!r}" for i, d, o in diffs)
    assert len(deb) == len(ours)


# ---------------------------------------------------------------- scenarios


def sc_basics(c: Client, fakes: FakeNodes) -> List[Any]:
    pid = c("getPid", "/n")
    uri = c("getUri", "/n")
    return [
        [pid[0], pid[1], isinstance(pid[2], int) and pid[2] > 0],
        [uri[0], uri[1], uri[2].startswith("http://") and uri[2].endswith(":PORT/")],
        c("getPid"),                       # no caller_id
        c("getPid", "/n", "extra"),        # bad arity
        c("getUri", 42),                   # caller_id not a string
        c("getParam", "/n"),
        c("getParam", ["/n"], "x"),
        c("shutdown", "/n"),               # shutdown takes caller_id and msg
        c("noSuchMethod", "/n"),
        c("_shutdown", "/n"),
        c("system.multicall", [{"methodName": "getUri", "params": [5]},
                               {"methodName": "nope", "params": ["/n"]},
                               {"methodName": "hasParam", "params": ["/n", "x"]}]),
        c("getSystemState", "/n"),
        c("getTopicTypes", "/n"),
        c("getPublishedTopics", "/n", ""),
        c("getParamNames", "/n"),
        c("getParam", "/n", "/"),
    ]


def sc_params(c: Client, fakes: FakeNodes) -> List[Any]:
    out = [
        c("setParam", "/sub/node", "p", 1),
        c("getParam", "/sub/node", "p"),
        c("getParam", "/", "/sub/p"),
        c("setParam", "/sub/node", "~priv", "x"),
        c("getParam", "/", "/sub/node/priv"),
        c("getParam", "/sub/node", "~priv"),
        c("hasParam", "/sub/node", "priv"),
        c("hasParam", "/", "/sub"),
        c("hasParam", "/", "/sub/"),
        c("hasParam", "/", "/nothing"),
        c("setParam", "/", "/ns", {"a": 1, "b": {"c": 2}}),
        c("setParam", "/", "/ns", {"d": 3}),  # replaces the namespace
        c("getParam", "/", "/ns"),
        c("getParam", "/", "/ns/a"),
        c("setParam", "/", "/scalar", 5),
        c("setParam", "/", "/scalar/below", 6),  # the scalar becomes a namespace
        c("getParam", "/", "/scalar"),
        c("setParam", "/", "/empty", {}),
        c("getParamNames", "/"),
        c("deleteParam", "/", "/ns/d"),
        c("deleteParam", "/", "/ns/d"),
        c("deleteParam", "/", "/"),
        c("deleteParam", "/", "/a/b/c/d"),
        c("setParam", "/", "/", 5),
        c("setParam", "/", "", 1),
        c("setParam", "/", 7, 1),
        c("getParam", "/", ""),
        c("getParam", "/", "//sub//p/"),
        c("hasParam", "/", 3),
        c("setParam", "/", "/types", {
            "b": True, "i": -2147483648, "f": 1.5e300, "s": "héllo ☃", "l": [1, "two", [3.0]],
            "bin": xmlrpc.client.Binary(b"\x00\x01\xff"),
            "dt": xmlrpc.client.DateTime("20260101T10:11:12")}),
        c("getParam", "/", "/types"),
        c("getParam", "/", "/"),
        c("setParam", "/", "/", {"fresh": 1}),
        c("getParamNames", "/"),
        c("getParam", "/", "/"),
    ]
    return out


def sc_search(c: Client, fakes: FakeNodes) -> List[Any]:
    out = [c("setParam", "/", "/robot_description", {"arm": 1, "base": 2}),
           c("setParam", "/", "/pr2/robot_description", {"base": 3}),
           c("setParam", "/", "/pr2/foo/own", 4),
           c("setParam", "/", "/top", 5)]
    for caller, key in [("/pr2/foo", "robot_description"), ("/pr2/foo", "robot_description/arm"),
                        ("/other/node", "robot_description/arm"), ("/pr2/foo", "own"),
                        ("/pr2/foo", "own/deeper"), ("/pr2/foo", "top"), ("/pr2/foo", "missing"),
                        ("/pr2/foo", "/top"), ("/pr2/foo", "/missing"), ("/pr2/foo", "~x"),
                        ("/pr2/foo", ""), ("relative", "top"), ("/", "top"),
                        ("/a/b/c/d", "pr2/robot_description")]:
        out.append(c("searchParam", caller, key))
    return out


def sc_topics(c: Client, fakes: FakeNodes) -> List[Any]:
    dead = fakes.dead()  # callbacks to it fail; replies must not wait for them
    a, b = "http://127.0.0.1:1001/", "http://127.0.0.1:1002/"
    start = time.monotonic()
    out = [
        c("registerSubscriber", "/ns/sub", "chatter", "*", dead),
        c("getTopicTypes", "/"),
        c("registerPublisher", "/ns/pub", "chatter", "*", a),
        c("getTopicTypes", "/"),
        c("registerPublisher", "/ns/pub", "chatter", "std_msgs/String", a),
        c("registerPublisher", "/ns/pub2", "chatter", "*", b),
        c("getTopicTypes", "/"),
        c("registerPublisher", "/ns/pub2", "/ns/chatter", "std_msgs/Int32", b),
        c("getTopicTypes", "/"),
        c("registerSubscriber", "/x", "/only_sub", "std_msgs/Empty", dead),
        c("registerSubscriber", "/x", "/only_sub", "std_msgs/Bool", dead),
        c("registerPublisher", "/p", "~private", "a/B", a),
        c("getPublishedTopics", "/", ""),
        c("getPublishedTopics", "/", "/ns"),
        c("getPublishedTopics", "/ns/node", "ns"),
        c("getPublishedTopics", "/", "/n"),
        c("getTopicTypes", "/"),
        c("getSystemState", "/"),
        c("lookupNode", "/", "/ns/pub"),
        c("lookupNode", "/ns/other", "pub"),
        c("lookupNode", "/", "/missing"),
        c("lookupNode", "/", "bad name"),
        c("unregisterPublisher", "/ns/pub", "chatter", b),  # wrong api
        c("unregisterPublisher", "/nobody", "chatter", a),
        c("unregisterPublisher", "/ns/pub", "chatter", a),
        c("lookupNode", "/", "/ns/pub"),  # stale: its only registration is gone
        c("unregisterSubscriber", "/ns/sub", "/ns/chatter", dead),
        c("unregisterSubscriber", "/ns/sub", "/ns/chatter", dead),
        c("getSystemState", "/"),
        c("getTopicTypes", "/"),
        # validators
        c("registerPublisher", "/n", "", "a/B", a),
        c("registerPublisher", "/n", "/", "a/B", a),
        c("registerPublisher", "/n", "a b", "a/B", a),
        c("registerPublisher", "/n", "http://x", "a/B", a),
        c("registerPublisher", "/n", 5, "a/B", a),
        c("registerPublisher", "/n", "t", "noslash", a),
        c("registerPublisher", "/n", "t", "a/b/c", a),
        c("registerPublisher", "/n", "t", "", a),
        c("registerPublisher", "/n", "t", "a/B", "ftp://x"),
        c("registerPublisher", "/n", "t", "a/B", ""),
        c("registerPublisher", "/n", "t", "a/B", "rosrpc://h:1"),
        c("registerSubscriber", "/n", "t", "a/B"),
        c("getPublishedTopics", "/", 5),
        c("getPublishedTopics", "/", "a:b"),
    ]
    elapsed = time.monotonic() - start
    out.append(elapsed < 5.0)  # a dead subscriber never delays a reply
    return out


def sc_nodes_and_services(c: Client, fakes: FakeNodes) -> List[Any]:
    old_api, old = fakes.new()
    new_api = "http://127.0.0.1:1003/"
    out = [
        c("registerService", "/srv_node", "add", "rosrpc://h:1", old_api),
        c("registerPublisher", "/srv_node", "t1", "a/B", old_api),
        c("subscribeParam", "/srv_node", old_api, "p"),
        c("lookupService", "/", "/add"),
        c("lookupService", "/", "add"),
        c("lookupService", "/", "/nothing"),
        c("registerService", "/other", "/add", "rosrpc://h:2", "http://127.0.0.1:1004/"),
        c("lookupService", "/", "/add"),
        c("unregisterService", "/srv_node", "/add", "rosrpc://h:1"),
        c("lookupNode", "/", "/srv_node"),
        c("unregisterService", "/other", "/add", "rosrpc://h:9"),
        c("unregisterService", "/other", "/add", "rosrpc://h:2"),
        c("unregisterService", "/other", "/add", "rosrpc://h:2"),
        c("unregisterService", "/ghost", "/add", "rosrpc://h:2"),
        c("lookupNode", "/", "/other"),
        c("registerService", "/n", "/s", "http://h:1", old_api),
        c("registerService", "/n", "/s", "tcp://h:1", old_api),
        c("getSystemState", "/"),
        # same name, new API: the old node is told to shut down and its registrations purged
        c("registerSubscriber", "/srv_node", "t2", "a/B", new_api),
        c("getSystemState", "/"),
        c("lookupNode", "/", "/srv_node"),
    ]
    calls = old.wait_for(1)
    out.append([call for call in calls if call[0] == "shutdown"])
    out.append(c("unsubscribeParam", "/srv_node", old_api, "p"))
    out.append(c("unsubscribeParam", "/nobody", old_api, "p"))
    out.append(c("unregisterSubscriber", "/srv_node", "t2", new_api))
    out.append(c("lookupNode", "/", "/srv_node"))
    return out


def sc_publisher_updates(c: Client, fakes: FakeNodes) -> List[Any]:
    sub_api, sub = fakes.new()
    pub1, pub2 = "http://127.0.0.1:2001/", "http://127.0.0.1:2002/"
    out = [
        c("registerSubscriber", "/s", "/t", "a/B", sub_api),
        c("registerPublisher", "/p1", "/t", "a/B", pub1),
        c("registerPublisher", "/p2", "/t", "a/B", pub2),
        c("unregisterPublisher", "/p1", "/t", pub1),
        c("unregisterPublisher", "/p1", "/t", pub1),  # no change: no update
        c("unregisterPublisher", "/p2", "/t", pub2),
    ]
    sub.wait_for(4)
    time.sleep(0.3)  # no further (unexpected) update may arrive; nothing to wait on for absence
    out.append(sub.calls)
    return out


def sc_param_updates(c: Client, fakes: FakeNodes) -> List[Any]:
    api1, rec1 = fakes.new()
    api2, rec2 = fakes.new()
    out = [
        c("subscribeParam", "/n1", api1, "/a"),
        c("subscribeParam", "/n1", api1, "/a/b/"),
        c("subscribeParam", "/n2", api2, "/a/b/c"),
        c("subscribeParam", "/n2", api2, "/a/x"),
    ]
    # Each step waits for the callbacks it causes, so later steps cannot race with them.
    steps = [
        (("setParam", "/n1", "/a/b/c", 1), 0, 1),            # the setter n1 is not told
        (("setParam", "/w", "/a/b", {"c": 2, "d": 3}), 2, 2),  # dict: sub-keys get their values
        (("setParam", "/w", "/a", {"b": {"d": 4}}), 4, 4),     # /a/b/c and /a/x vanish -> {}
        (("deleteParam", "/w", "/a/b"), 6, 5),
        (("setParam", "/w", "/unrelated", 1), 6, 5),
    ]
    for call, count1, count2 in steps:
        out.append(c(*call))
        out.append([len(rec1.wait_for(count1)), len(rec2.wait_for(count2))])
    out.append(c("subscribeParam", "/n1", api1, "/a"))
    time.sleep(0.3)  # give a surplus (wrong) update the chance to show up in the comparison
    out.append(rec1.calls)
    out.append(rec2.calls)
    return out


def sc_bad_input(c: Client, fakes: FakeNodes) -> List[Any]:
    def fault_kind(result: Any) -> Any:
        if result and result[0] == "FAULT":
            return ["FAULT", result[1], result[2].split(":")[0]]
        return result

    nil_call = (b"<?xml version='1.0'?><methodCall><methodName>setParam</methodName><params>"
                b"<param><value><string>/n</string></value></param>"
                b"<param><value><string>/k</string></value></param>"
                b"<param><value><nil/></value></param></params></methodCall>")
    big_int = (b"<?xml version='1.0'?><methodCall><methodName>setParam</methodName><params>"
               b"<param><value><string>/n</string></value></param>"
               b"<param><value><string>/big</string></value></param>"
               b"<param><value><i8>4294967296</i8></value></param></params></methodCall>")
    return [
        fault_kind(c.raw(b"<methodCall><methodName>getPid</methodName><params>")),
        fault_kind(c.raw(b"not xml at all")),
        fault_kind(c.raw(b"<methodResponse><params><param><value><int>1</int></value></param>"
                         b"</params></methodResponse>")),
        c.raw(nil_call),
        c.raw(big_int),
        fault_kind(c("getParam", "/n", "/big")),
        c("getPid", "/still/alive")[0],
    ]


@pytest.mark.parametrize("scenario", [sc_basics, sc_params, sc_search, sc_topics,
                                      sc_nodes_and_services, sc_publisher_updates,
                                      sc_param_updates, sc_bad_input],
                         ids=lambda f: f.__name__[3:])
def test_same_results_as_rosmaster(both, scenario):
    run_both(both, scenario)


# ---------------------------------------------------------------- robustness, per master


@pytest.fixture(params=["debian", "minros"])
def master_port(request):
    return request.getfixturevalue("debian_rosmaster" if request.param == "debian"
                                   else "minros_master")


def _answers_promptly(port: int, limit: float = 1.0) -> bool:
    start = time.monotonic()
    proxy = xmlrpc.client.ServerProxy(f"http://127.0.0.1:{port}/")
    code, _msg, _pid = proxy.getPid("/probe")
    return code == 1 and time.monotonic() - start < limit


def test_silent_clients_do_not_block(master_port):
    silent = [socket.create_connection(("127.0.0.1", master_port), timeout=5) for _ in range(50)]
    half = socket.create_connection(("127.0.0.1", master_port), timeout=5)
    half.sendall(b"POST / HTTP/1.1\r\nContent-Length: 1000\r\n\r\n<method")  # never finished
    try:
        assert _answers_promptly(master_port)
    finally:
        for s in silent + [half]:
            s.close()


def test_entity_expansion_bomb(master_port):
    entities = "".join(f'<!ENTITY e{i} "{f"&e{i - 1};" * 10}">' for i in range(1, 12))
    bomb = (f'<?xml version="1.0"?><!DOCTYPE m [<!ENTITY e0 "boom">{entities}]>'
            "<methodCall><methodName>getParam</methodName><params><param><value>"
            "<string>&e11;</string></value></param></params></methodCall>").encode()
    c = Client(master_port, {})
    start = time.monotonic()
    result = c.raw(bomb)
    assert result[0] == "FAULT"
    assert time.monotonic() - start < 5
    assert _answers_promptly(master_port)


def test_oversize_body_is_refused_by_minros(minros_master):
    with socket.create_connection(("127.0.0.1", minros_master), timeout=5) as s:
        s.sendall(b"POST / HTTP/1.1\r\nContent-Length: 4294967296\r\n\r\n")
        reply = s.recv(4096)
    assert reply.startswith(b"HTTP/1.1 413")
    assert _answers_promptly(minros_master)


def test_300_concurrent_clients(master_port):
    errors: List[Any] = []
    barrier = threading.Barrier(300, timeout=20)

    def client(i: int) -> None:
        try:
            proxy = xmlrpc.client.ServerProxy(f"http://127.0.0.1:{master_port}/")
            barrier.wait()
            for j in range(3):
                code, _msg, _val = proxy.setParam(f"/c{i}", f"~p{j}", i * 10 + j)
                assert code == 1
                assert proxy.getParam(f"/c{i}", f"~p{j}")[2] == i * 10 + j
        except Exception as exc:  # noqa: BLE001 - collected and reported below
            errors.append(exc)

    threads = [threading.Thread(target=client, args=(i,)) for i in range(300)]
    start = time.monotonic()
    for t in threads:
        t.start()
    for t in threads:
        t.join(30)
    assert not errors, errors[:3]
    assert time.monotonic() - start < 25
    assert len(xmlrpc.client.ServerProxy(f"http://127.0.0.1:{master_port}/")
               .getParamNames("/")[2]) == 900
