"""The master's pure parts: parameter tree, paramUpdate fan-out, registrations, API validation,
and the callback pool's ordering (no sockets except where a real slow node is simulated)."""

from __future__ import annotations

import threading

import pytest

from minros.master import (
    CallbackPool,
    MasterHandler,
    ParamTree,
    RegistrationManager,
    Registrations,
    compute_param_updates,
)


class FakePool:
    """Records queued callbacks instead of calling nodes."""

    def __init__(self) -> None:
        self.calls = []

    def queue(self, api, method, args, coalesce=None, on_result=None):
        self.calls.append((api, method, args))


# ---------------------------------------------------------------- parameter tree


def test_dict_set_replaces_namespace():
    t = ParamTree()
    t.set("/ns", {"a": 1, "b": {"c": 2}})
    t.set("/ns", {"d": 3})
    assert t.get("/ns") == {"d": 3}
    with pytest.raises(KeyError):
        t.get("/ns/a")


def test_implicit_namespaces_and_scalar_conversion():
    t = ParamTree()
    t.set("/a/b/c", 1)
    assert t.get("/a") == {"b": {"c": 1}}
    t.set("/s", 5)
    t.set("/s/x", 6)  # /s was a scalar: it silently becomes a namespace
    assert t.get("/s") == {"x": 6}
    assert t.has("/a/") and t.has("/a") and not t.has("/a/b/c/d")
    assert t.get("/") == {"a": {"b": {"c": 1}}, "s": {"x": 6}}


def test_root_rules_and_delete():
    t = ParamTree()
    with pytest.raises(TypeError):
        t.set("/", 5)
    t.set("/", {"x": {"y": 1}})
    with pytest.raises(KeyError):
        t.delete("/")
    with pytest.raises(KeyError):
        t.delete("/nothing/y")
    with pytest.raises(TypeError):  # below a scalar: rosmaster reports "invalid arguments"
        t.delete("/x/y/z")
    t.delete("/x/y")
    assert t.get("/x") == {}
    with pytest.raises(KeyError):
        t.delete("/x/y")


def test_param_names_lists_leaves_only():
    t = ParamTree()
    t.set("/a", {"b": 1, "c": {"d": 2}, "e": {}})
    t.set("/f", [1, 2])
    assert t.names() == ["/a/b", "/a/c/d", "/f"]


@pytest.mark.parametrize("ns, key, expected", [
    ("/pr2/foo", "robot_description", "/pr2/robot_description"),
    ("/pr2/foo", "robot_description/arm", "/pr2/robot_description/arm"),  # need not exist
    ("/other/node", "robot_description/arm", "/robot_description/arm"),
    ("/pr2/foo", "own", "/pr2/foo/own"),  # private namespace first
    ("/pr2/foo", "missing", None),
    ("/pr2/foo", "/top", "/top"),
    ("/pr2/foo", "/missing", None),
])
def test_search(ns, key, expected):
    t = ParamTree()
    t.set("/robot_description", {"arm": 1})
    t.set("/pr2/robot_description", {"base": 3})
    t.set("/pr2/foo/own", 4)
    t.set("/top", 5)
    assert t.search(ns, key) == expected


def test_search_rejects_private_keys_and_relative_callers():
    t = ParamTree()
    for ns, key in [("/n", "~x"), ("/n", ""), ("relative", "x")]:
        with pytest.raises(ValueError):
            t.search(ns, key)


# ---------------------------------------------------------------- paramUpdate fan-out


def _subs(*entries):
    regs = Registrations(Registrations.PARAM_SUBSCRIPTIONS)
    for key, caller in entries:
        regs.register(key, caller, f"http://{caller.strip('/')}:1/")
    return regs


def test_updates_use_trailing_slash_keys_and_skip_the_setter():
    subs = _subs(("/a/", "/n1"), ("/a/b/", "/n2"))
    updates = compute_param_updates(subs, "/a/b", 5, caller_to_ignore="/n1")
    assert updates == [([], "/a/b/", 5), ([("/n2", "http://n2:1/")], "/a/b/", 5)]


def test_dict_set_notifies_sub_keys_and_sends_empty_dict_for_removed():
    subs = _subs(("/a/b/c/", "/n"), ("/a/x/", "/m"), ("/a/", "/k"))
    updates = compute_param_updates(subs, "/a", {"b": {"c": 7}})
    assert ([("/m", "http://m:1/")], "/a/x/", {}) in updates
    assert ([("/n", "http://n:1/")], "/a/b/c/", 7) in updates
    assert ([("/k", "http://k:1/")], "/a/", {"b": {"c": 7}}) in updates
    assert len(updates) == 3


def test_delete_is_an_empty_dict_update():
    subs = _subs(("/a/b/c/", "/n"), ("/a/", "/k"), ("/z/", "/z"))
    updates = compute_param_updates(subs, "/a/b", {})
    assert sorted(u[1] for u in updates) == ["/a/b/", "/a/b/c/"]
    assert all(u[2] == {} for u in updates)


def test_handler_fans_out_param_updates_with_snapshots():
    pool = FakePool()
    h = MasterHandler(pool)
    assert h.subscribeParam("/n", "http://n:1/", "/a") == [1, "Subscribed to parameter [/a]", {}]
    h.setParam("/w", "/a", {"b": 1})
    h.setParam("/w", "/a/c", 2)  # mutates the tree's /a dict in place
    assert pool.calls[0] == ("http://n:1/", "paramUpdate", ("/master", "/a/", {"b": 1}))
    assert pool.calls[1] == ("http://n:1/", "paramUpdate", ("/master", "/a/c/", 2))
    h.setParam("/n", "/a/d", 3)  # the subscriber itself set it: not told
    assert len(pool.calls) == 2


# ---------------------------------------------------------------- registrations


def test_star_type_never_squashes_known_type():
    h = MasterHandler(FakePool())
    h.registerSubscriber("/s", "/t", "*", "http://s:1/")
    assert h.getTopicTypes("/")[2] == []
    h.registerPublisher("/p", "/t", "*", "http://p:1/")
    assert h.getTopicTypes("/")[2] == [["/t", "*"]]
    h.registerPublisher("/p", "/t", "std_msgs/String", "http://p:1/")
    h.registerPublisher("/q", "/t", "*", "http://q:1/")
    assert h.getTopicTypes("/")[2] == [["/t", "std_msgs/String"]]
    h.registerSubscriber("/s2", "/u", "a/B", "http://s2:1/")
    h.registerSubscriber("/s3", "/u", "a/C", "http://s3:1/")
    assert ["/u", "a/B"] in h.getTopicTypes("/")[2]
    assert h.getPublishedTopics("/", "")[2] == [["/t", "std_msgs/String"]]


def test_same_name_new_api_bumps_and_purges_old_node():
    bumped = []
    reg = RegistrationManager(on_bump=lambda api, cid: bumped.append((api, cid)))
    reg.register_publisher("/t", "/n", "http://old:1/")
    reg.register_service("/s", "/n", "http://old:1/", "rosrpc://old:2")
    reg.register_param_subscriber("/p/", "/n", "http://old:1/")
    reg.register_subscriber("/u", "/n", "http://new:1/")
    assert bumped == [("http://old:1/", "/n")]
    assert reg.publishers.get_state() == []
    assert reg.services.get_state() == [] and reg.services.get_service_api("/s") is None
    assert not reg.param_subscribers
    assert reg.subscribers.get_state() == [["/u", ["/n"]]]
    assert reg.get_node("/n").api == "http://new:1/"


def test_node_forgotten_with_its_last_registration():
    h = MasterHandler(FakePool())
    h.registerPublisher("/n", "/t", "a/B", "http://n:1/")
    h.registerSubscriber("/n", "/u", "a/B", "http://n:1/")
    assert h.lookupNode("/", "/n") == [1, "node api", "http://n:1/"]
    assert h.unregisterPublisher("/n", "/t", "http://n:1/")[2] == 1
    assert h.lookupNode("/", "/n")[0] == 1
    assert h.unregisterSubscriber("/n", "/u", "http://n:1/")[2] == 1
    assert h.lookupNode("/", "/n") == [-1, "unknown node [/n]", ""]
    assert h.unregisterSubscriber("/n", "/u", "http://n:1/") == [
        1, "[/n] is not a registered node", 0]


def test_publisher_updates_go_to_every_subscriber():
    pool = FakePool()
    h = MasterHandler(pool)
    h.registerSubscriber("/s1", "/t", "a/B", "http://s1:1/")
    h.registerSubscriber("/s2", "/t", "a/B", "http://s2:1/")
    assert h.registerPublisher("/p", "/t", "a/B", "http://p:1/")[2] == ["http://s1:1/",
                                                                       "http://s2:1/"]
    assert pool.calls == [("http://s1:1/", "publisherUpdate", ("/master", "/t", ["http://p:1/"])),
                          ("http://s2:1/", "publisherUpdate", ("/master", "/t", ["http://p:1/"]))]
    h.unregisterPublisher("/p", "/t", "http://wrong:1/")
    assert len(pool.calls) == 2  # nothing changed: nobody told
    h.unregisterPublisher("/p", "/t", "http://p:1/")
    assert pool.calls[-1] == ("http://s2:1/", "publisherUpdate", ("/master", "/t", []))


def test_services_last_registration_wins():
    h = MasterHandler(FakePool())
    h.registerService("/a", "/s", "rosrpc://a:1", "http://a:1/")
    h.registerService("/b", "/s", "rosrpc://b:1", "http://b:1/")
    assert h.lookupService("/", "/s")[2] == "rosrpc://b:1"
    assert h.unregisterService("/a", "/s", "rosrpc://a:1")[2] == 0
    assert h.unregisterService("/b", "/s", "rosrpc://b:1")[2] == 1
    assert h.lookupService("/", "/s") == [-1, "no provider", ""]


# ---------------------------------------------------------------- validation


def test_api_validation_triplets():
    h = MasterHandler(FakePool())
    assert h.getParam() == [-1, "missing required caller_id parameter", 0]
    assert h.getParam("/n") == [-1, "Error: bad call arity", 0]
    assert h.getParam(5, "x") == [-1, "caller_id must be a string", 0]
    assert h.getParam("/n", "") == [-1, "ERROR: parameter [key] must be specified and non-empty", 0]
    assert h.hasParam("/n", 4) == [-1, "ERROR: parameter [key] must be a string", False]
    assert h.registerPublisher("/n", "/", "a/B", "http://x:1/")[:2] == [
        -1, "ERROR: parameter [topic] cannot be the global namespace"]
    assert h.registerPublisher("/n", "t", "ab", "http://x:1/")[:2] == [
        -1, "ERROR: parameter [topic_type] is not a valid package resource name"]
    assert h.registerPublisher("/n", "t", "a/B", "x")[:2] == [
        -1, "ERROR: parameter [caller_api] is not an RPC URI"]
    assert h.setParam("/n", "/", 5) == [
        -1, "Error: invalid arguments: cannot set root of parameter tree to non-dictionary", 0]
    assert h.searchParam("/n", "~x") == [0, "Internal failure: invalid key", 0]
    assert h.hasParam("/sub/node", "p") == [1, "/sub/p", False]


# ---------------------------------------------------------------- callback pool


def test_callback_pool_orders_per_node_and_isolates_slow_nodes():
    seen = []
    slow_release = threading.Event()
    done = threading.Event()

    def call(api, method, args):
        if api == "slow":
            slow_release.wait(5)
        seen.append((api, args[0]))
        if len([s for s in seen if s[0] == "fast"]) == 50:
            done.set()
        return [1, "", 0]

    pool = CallbackPool(workers=3, call=call)
    try:
        pool.queue("slow", "publisherUpdate", (0,))
        for i in range(50):
            pool.queue("fast", "publisherUpdate", (i,))
        assert done.wait(5), "a slow node delayed callbacks to another node"
        assert [i for api, i in seen if api == "fast"] == list(range(50))
        slow_release.set()
        assert pool.join(5) and pool.pending() == 0
        assert ("slow", 0) in seen
    finally:
        pool.stop()


def test_callback_pool_coalesces_only_a_backlog():
    release = threading.Event()
    seen = []

    def call(api, method, args):
        release.wait(5)
        seen.append(args)
        return [1, "", 0]

    pool = CallbackPool(workers=1, call=call)
    try:
        for i in range(200):
            pool.queue("n", "publisherUpdate", ("/master", "/t", [i]), coalesce=("pu", "/t"))
        release.set()
        assert pool.join(5)
        assert seen[-1] == ("/master", "/t", [199])  # the latest state always arrives
        assert len(seen) < 200
    finally:
        pool.stop()



def test_namespaces_are_handed_out_as_snapshots():
    # getParam's value is marshalled after the lock is released: a later setParam below the
    # namespace must not change it underneath (that would break serialization mid-way)
    h = MasterHandler(FakePool())
    h.setParam("/w", "/ns", {"a": {"b": 1}})
    value = h.getParam("/r", "/ns")[2]
    subscribed = h.subscribeParam("/r", "http://r:1/", "/ns")[2]
    h.setParam("/w", "/ns/a/c", 2)
    h.setParam("/w", "/ns/d", 3)
    assert value == {"a": {"b": 1}} and subscribed == {"a": {"b": 1}}
    assert h.getParam("/r", "/ns")[2] == {"a": {"b": 1, "c": 2}, "d": 3}


# ---------------------------------------------------------------- graph watchers (minros extension)


class RecordingPool:
    """Records queued callbacks with their on_result, so a test can answer them."""

    def __init__(self) -> None:
        self.calls = []

    def queue(self, api, method, args, coalesce=None, on_result=None):
        self.calls.append((api, method, args, on_result))

    def answer(self, index, result):
        self.calls[index][3](result)


NODE_API = "http://node:1/"
WATCHER = "http://watcher:2/"


def test_graph_watcher_gets_one_update_in_flight_then_the_newest_version():
    pool = RecordingPool()
    h = MasterHandler(pool)
    code, _msg, version = h.subscribeGraph("/web", WATCHER)
    assert code == 1 and version == 0
    h.registerPublisher("/talker", "/chatter", "std_msgs/String", NODE_API)
    updates = [c for c in pool.calls if c[1] == "graphUpdate"]
    assert [(c[0], c[2]) for c in updates] == [(WATCHER, ("/master", 1))]
    # a burst while the first update is in flight queues nothing more ...
    h.registerSubscriber("/listener", "/chatter", "std_msgs/String", "http://node:3/")
    h.registerService("/talker", "/srv", "rosrpc://node:4", NODE_API)
    assert len([c for c in pool.calls if c[1] == "graphUpdate"]) == 1
    # ... and its answer sends the newest version once
    pool.answer(pool.calls.index(updates[0]), [1, "", 0])
    updates = [c for c in pool.calls if c[1] == "graphUpdate"]
    assert [c[2] for c in updates] == [("/master", 1), ("/master", 3)]
    pool.answer(pool.calls.index(updates[1]), [1, "", 0])
    assert len([c for c in pool.calls if c[1] == "graphUpdate"]) == 2  # up to date: quiet


def test_graph_watcher_is_dropped_when_it_fails_and_unregistering_nothing_is_no_change():
    pool = RecordingPool()
    h = MasterHandler(pool)
    h.subscribeGraph("/web", WATCHER)
    h.unregisterPublisher("/talker", "/nothing", NODE_API)  # nothing was registered
    assert not [c for c in pool.calls if c[1] == "graphUpdate"]
    h.registerPublisher("/talker", "/chatter", "std_msgs/String", NODE_API)
    pool.answer(len(pool.calls) - 1, ConnectionRefusedError(111, "refused"))
    h.unregisterPublisher("/talker", "/chatter", NODE_API)
    assert len([c for c in pool.calls if c[1] == "graphUpdate"]) == 1  # the dead one is gone
    code, _msg, version = h.subscribeGraph("/web", WATCHER)
    assert code == 1 and version == 2
    assert h.unsubscribeGraph("/web", WATCHER)[2] == 1
    assert h.unsubscribeGraph("/web", WATCHER)[2] == 0
    assert h.subscribeGraph("/web", "not a uri")[0] == -1


def test_graph_watchers_are_bounded():
    from minros.master import MAX_GRAPH_WATCHERS

    h = MasterHandler(RecordingPool())
    for i in range(MAX_GRAPH_WATCHERS):
        assert h.subscribeGraph("/web", f"http://w:{i + 1}/")[0] == 1
    code, msg, _ = h.subscribeGraph("/web", "http://w:9999/")
    assert code == -1 and "too many graph watchers" in msg
    assert h.subscribeGraph("/web", "http://w:1/")[0] == 1  # a known watcher renews
