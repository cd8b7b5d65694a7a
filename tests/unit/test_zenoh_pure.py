"""The pure parts of ``minros zenoh``: key expressions against golden vectors of the
zenoh-bridge-ros1 wire format, the beacon table, the bridging plan, the layout check and the
minros topic record. No Zenoh here: these run without the extra."""

from __future__ import annotations

import io
import random

import pytest

from minros.msgs import generate_dynamic, get_message_class
from minros.zenoh import keys, layout, meta
from minros.zenoh.discovery import Declarations, OnceLog, RemoteTable
from minros.zenoh.keys import KeyMappingError, Resource
from minros.zenoh.plan import plan

STRING_MD5 = "992ce8a1687cec8c8bd883ec73ca41d1"
SETBOOL_MD5 = "09fb03525b03e7ea1fd3992bafd87e16"


# -- golden vectors ---------------------------------------------------------------------------
# RosLibRust/roslibrust roslibrust_zenoh/src/lib.rs (commit 3ae7289), tests test_mangle_topic,
# test_mangle_service, test_make_discovery_key, test_parse_discovery_key: a client written
# against zenoh-plugin-ros1 after its PR #225 ("{data_type}/{md5}/{bridge_namespace}/{topic}").

def test_golden_topic_key():
    assert keys.data_key("/chatter", "std_msgs/String", STRING_MD5) == (
        "7374645f6d7367732f537472696e67/992ce8a1687cec8c8bd883ec73ca41d1/*/chatter")


def test_golden_service_key():
    assert keys.data_key("/service_server_rs/my_set_bool", "std_srvs/SetBool", SETBOOL_MD5) == (
        "7374645f737276732f536574426f6f6c/09fb03525b03e7ea1fd3992bafd87e16/*/"
        "service_server_rs/my_set_bool")


def test_golden_discovery_key_and_its_parse():
    key = ("ros1_discovery_info/*/srv/7374645f737276732f536574426f6f6c/"
           "09fb03525b03e7ea1fd3992bafd87e16/*/service_server_rs/my_set_bool")
    assert keys.discovery_key("srv", "/service_server_rs/my_set_bool", "std_srvs/SetBool",
                              SETBOOL_MD5) == key
    assert keys.parse_discovery_key(key) == Resource(
        "srv", "/service_server_rs/my_set_bool", "std_srvs/SetBool", SETBOOL_MD5, "*")


def test_discovery_subscription_is_the_bridges():
    # zenoh-plugin-ros1 discovery.rs: discovery_format with every field "*" and topic "*/**"
    assert keys.discovery_subscription() == "ros1_discovery_info/*/*/*/*/*/*/**"
    assert keys.discovery_subscription("robot1") == "ros1_discovery_info/*/*/*/*/robot1/*/**"


def test_topic_names_lose_their_outer_slashes_only():
    # topic_utilities.rs make_topic_key: trim_start_matches('/').trim_end_matches('/')
    assert keys.data_key("/a/b/c/", "std_msgs/String", STRING_MD5).endswith("/*/a/b/c")
    assert keys.data_key("/x", "std_msgs/String", STRING_MD5, "robot1").endswith("/robot1/x")


@pytest.mark.parametrize("name", ["/", "", "/a//b", "/a/*", "/a/$x", "/a b"])
def test_names_that_map_to_no_key_are_refused(name):
    with pytest.raises(KeyMappingError, match="not a ROS graph name"):
        keys.data_key(name, "std_msgs/String", STRING_MD5)


@pytest.mark.parametrize("key, reason", [
    ("ros1_discovery_info/*/pub", "not a discovery key"),
    ("other/*/pub/7374/992ce8a1687cec8c8bd883ec73ca41d1/*/x", "not a discovery key"),
    ("ros1_discovery_info/*/bad/7374645f6d7367732f537472696e67/" + STRING_MD5 + "/*/x",
     "unknown resource class"),
    ("ros1_discovery_info/*/pub/zz/" + STRING_MD5 + "/*/x", "not hex"),
    ("ros1_discovery_info/*/pub/ff/" + STRING_MD5 + "/*/x", "not UTF-8"),
    ("ros1_discovery_info/*/pub/7374645f6d7367732f537472696e67/notmd5/*/x", "not an md5sum"),
    ("ros1_discovery_info/*/pub/" + b"abc".hex() + "/" + STRING_MD5 + "/*/x",
     "not a ROS type name"),
])
def test_bad_discovery_keys_say_why(key, reason):
    with pytest.raises(KeyMappingError, match=reason):
        keys.parse_discovery_key(key)


def test_key_round_trip_on_random_names():
    rng = random.Random(7)
    alphabet = "abcdefghijklmnopqrstuvwxyz_0123456789"
    for _ in range(300):
        name = "/" + "/".join("".join(rng.choice(alphabet) for _ in range(rng.randint(1, 8)))
                              for _ in range(rng.randint(1, 4)))
        kind = rng.choice(keys.CLASSES)
        key = keys.discovery_key(kind, name, "geometry_msgs/Twist", "9f195f881246fdfa2798d1d3eebca84a")
        assert keys.parse_discovery_key(key) == Resource(
            kind, name, "geometry_msgs/Twist", "9f195f881246fdfa2798d1d3eebca84a")


# -- beacons ----------------------------------------------------------------------------------

def _beacon(kind="pub", name="/chatter"):
    return keys.discovery_key(kind, name, "std_msgs/String", STRING_MD5)


def test_a_resource_is_new_once_and_lost_after_three_silent_seconds():
    table = RemoteTable()
    res = table.heard(_beacon(), 10.0)
    assert res == Resource("pub", "/chatter", "std_msgs/String", STRING_MD5)
    assert table.heard(_beacon(), 11.0) is None  # a repeat is not news
    assert table.expire(13.9) == []
    assert table.expire(14.01) == [res]
    assert table.resources() == frozenset()
    assert table.heard(_beacon(), 15.0) == res  # heard again: new again


def test_the_table_is_bounded():
    table = RemoteTable(max_entries=3)
    for i in range(3):
        table.heard(_beacon(name=f"/t{i}"), 0.0)
    with pytest.raises(KeyMappingError, match="more than 3 remote resources"):
        table.heard(_beacon(name="/t3"), 0.0)
    assert table.heard(_beacon(name="/t0"), 1.0) is None  # known ones are still refreshed


def test_declarations_send_new_keys_at_once_then_every_period():
    decl = Declarations("*")
    a = Resource("pub", "/a", "std_msgs/String", STRING_MD5)
    b = Resource("sub", "/b", "std_msgs/String", STRING_MD5)
    decl.update({a}, 0.0)
    assert decl.due(0.0) == [_beacon("pub", "/a")]
    assert decl.due(0.5) == []
    decl.update({a, b}, 0.5)
    assert decl.due(0.5) == [_beacon("sub", "/b")]
    assert decl.due(1.0) == [_beacon("pub", "/a")]
    decl.update({b}, 1.2)
    assert decl.keys() == [_beacon("sub", "/b")]


def test_once_log_logs_each_fault_once_and_stays_bounded():
    lines = []
    once = OnceLog(lines.append, limit=3)
    for i in range(10):
        once(f"bad key {i % 5}")
    assert lines == ["bad key 0", "bad key 1", "bad key 2",
                     "more than 3 distinct faults: further ones are not logged"]


# -- the plan ---------------------------------------------------------------------------------

def R(kind, name, type_="std_msgs/String", md5=STRING_MD5):
    return Resource(kind, name, type_, md5)


def test_plan_carries_each_direction():
    p = plan(local=[R("pub", "/out"), R("sub", "/in"), R("srv", "/local_srv", "std_srvs/SetBool", SETBOOL_MD5)],
             remote=[R("pub", "/far"), R("sub", "/wanted"), R("srv", "/far_srv", "std_srvs/SetBool", SETBOOL_MD5),
                     R("cl", "/whatever", "std_srvs/SetBool", SETBOOL_MD5)])
    assert {t[0] for t in p.outlets} == {"/out", "/wanted"}
    assert {t[0] for t in p.inlets} == {"/in", "/far"}
    assert {t[0] for t in p.queryables} == {"/local_srv"}
    assert {t[0] for t in p.proxies} == {"/far_srv"}
    assert {r.name for r in p.declare} == {"/out", "/in", "/local_srv"}
    assert p.conflicts == ()


def test_a_remote_service_served_here_too_is_not_proxied():
    srv = R("srv", "/add", "std_srvs/SetBool", SETBOOL_MD5)
    p = plan(local=[srv], remote=[srv])
    assert p.proxies == frozenset() and p.queryables == {srv.topic}


def test_types_meeting_on_one_name_prefer_the_local_node_and_are_reported():
    other = "0123456789abcdef0123456789abcdef"
    p = plan(local=[R("sub", "/x")], remote=[R("pub", "/x", "other_msgs/Thing", other)])
    assert p.inlets == {("/x", "std_msgs/String", STRING_MD5)}
    assert p.conflicts == (f"topic /x has several types: bridging std_msgs/String ({STRING_MD5}), "
                           f"not other_msgs/Thing ({other})",)


# -- the layout check -------------------------------------------------------------------------

def _bytes(msg):
    buff = io.BytesIO()
    msg.serialize(buff)
    return buff.getvalue()


def _installed(name):
    return layout.checker(name, lambda t: list(get_message_class(t)._slot_types))


@pytest.mark.parametrize("type_name", [
    "std_msgs/String", "sensor_msgs/Image", "sensor_msgs/CameraInfo", "tf2_msgs/TFMessage",
    "visualization_msgs/MarkerArray", "geometry_msgs/Twist", "std_msgs/Empty",
    "sensor_msgs/PointCloud2", "diagnostic_msgs/DiagnosticArray"])
def test_layout_accepts_real_messages_and_refuses_damaged_ones(type_name):
    cls = get_message_class(type_name)
    check = _installed(type_name)
    rng = random.Random(type_name)
    msg = cls()
    if type_name == "sensor_msgs/Image":
        msg = cls(height=2, width=3, encoding="rgb8", step=9, data=bytes(range(18)))
    elif type_name == "visualization_msgs/MarkerArray":
        marker = get_message_class("visualization_msgs/Marker")(ns="a", text="hello")
        marker.points = [get_message_class("geometry_msgs/Point")(x=1.0)] * 3
        msg = cls(markers=[marker, marker])
    elif type_name == "tf2_msgs/TFMessage":
        t = get_message_class("geometry_msgs/TransformStamped")(child_frame_id="child")
        msg = cls(transforms=[t] * 4)
    data = _bytes(msg)
    check(data)
    check(memoryview(data))
    cut_points = [len(data) - 1] if data else []
    cut_points += [rng.randrange(len(data)) for _ in range(5)] if len(data) > 1 else []
    for cut in cut_points:
        with pytest.raises(layout.Malformed):
            check(data[:cut])
    with pytest.raises(layout.Malformed):
        check(data + b"\x00")


def test_layout_refuses_lengths_that_lie_without_looping_on_them():
    check = _installed("visualization_msgs/MarkerArray")
    with pytest.raises(layout.Malformed, match="cannot fit"):
        check(b"\xff\xff\xff\xff" + b"\x00" * 64)
    with pytest.raises(layout.Malformed):
        _installed("std_msgs/String")(b"\x10\x00\x00\x00abc")
    with pytest.raises(layout.Malformed, match="bytes where std_msgs/Float64 has 8"):
        _installed("std_msgs/Float64")(b"\x00" * 7)


def test_layout_from_a_carried_definition():
    text = get_message_class("sensor_msgs/Image")._full_text
    classes = generate_dynamic("sensor_msgs/Image", text)
    check = layout.checker("sensor_msgs/Image", layout.slot_types_from_classes(classes))
    image = get_message_class("sensor_msgs/Image")(encoding="mono8", data=b"abc", height=1, width=3, step=3)
    check(_bytes(image))
    with pytest.raises(layout.Malformed):
        check(b"garbage")


# -- the minros topic record ------------------------------------------------------------------

def test_meta_round_trip_and_refusals():
    record = meta.TopicMeta("std_msgs/String", STRING_MD5, "string data\n", True, b"\x01\x00\x00\x00x")
    assert meta.decode(meta.encode(record)) == record
    empty = meta.TopicMeta("std_msgs/Empty", "d41d8cd98f00b204e9800998ecf8427e", "", True, b"")
    assert meta.decode(meta.encode(empty)).latched == b""
    none = meta.TopicMeta("std_msgs/String", STRING_MD5)
    assert meta.decode(meta.encode(none)).latched is None
    for bad, reason in [(b"garbage", "not a minros topic record"),
                        (b"MRZ1\xff\xff\xff\x7f{}", "claims"),
                        (b"MRZ1\x02\x00\x00\x00[]", "not an object"),
                        (b"MRZ1\x02\x00\x00\x00{}", "field 'type'"),
                        (meta.encode(none) + b"x", "without a latched message")]:
        with pytest.raises(meta.MetaError, match=reason):
            meta.decode(bad)


# -- what remote beacons may create -------------------------------------------------------------

def test_the_first_heard_keep_their_bridges_under_the_cap():
    from minros.zenoh.plan import limit_remote, remote_only

    local = {R("sub", "/wanted"), R("pub", "/mine")}
    remote = {R("pub", "/wanted"), R("pub", "/early"), R("sub", "/asked"), R("srv", "/svc"),
              *(R("pub", f"/flood{i}") for i in range(10))}
    first = {r.topic: float(i) for i, r in enumerate(sorted(remote, key=lambda r: r.name))}
    first[("/early", "std_msgs/String", STRING_MD5)] = -1.0  # heard before the flood
    first[("/svc", "std_msgs/String", STRING_MD5)] = -0.5
    wanted = plan(local, remote)
    only = remote_only(wanted, local)
    assert ("/wanted", "std_msgs/String", STRING_MD5) not in only["inlets"]  # a local subscriber
    limited, dropped = limit_remote(wanted, local, first, cap=3)
    assert dropped == len(only["inlets"]) + len(only["outlets"]) + len(only["proxies"]) - 3
    names = {t[0] for t in limited.inlets | limited.outlets | limited.proxies}
    # what the local graph asks for is never dropped; of the rest, the first heard stay
    assert {"/wanted", "/mine", "/early", "/svc"} <= names
    assert len(names - {"/wanted", "/mine"}) == 3
    assert limit_remote(wanted, local, first, cap=100) == (wanted, 0)


def test_the_table_says_when_each_topic_was_first_heard_and_refuses_when_full():
    from minros.zenoh.discovery import TableFull

    table = RemoteTable(max_entries=2)
    table.heard(_beacon("pub", "/a"), 1.0)
    table.heard(_beacon("sub", "/a"), 2.0)
    table.heard(_beacon("pub", "/a"), 5.0)  # a repeat keeps the first time
    assert table.first_heard() == {("/a", "std_msgs/String", STRING_MD5): 1.0}
    with pytest.raises(TableFull):
        table.heard(_beacon("pub", "/b"), 5.0)
    assert len(table) == 2


def test_token_bucket_bound_log_and_chatter():
    from minros.zenoh.discovery import BoundLog, Chatter, TokenBucket

    bucket = TokenBucket(rate=10.0, burst=5.0, now=0.0)
    assert sum(bucket.take(0.0) for _ in range(20)) == 5  # the burst, then nothing
    assert sum(bucket.take(0.5) for _ in range(20)) == 5  # 0.5 s at 10/s, capped by the burst
    lines = []
    bound = BoundLog(lines.append, interval=60.0)
    assert bound("count", "at the bound", 0.0)
    assert not any(bound("count", "at the bound", t) for t in range(1, 60))
    assert bound("count", "at the bound", 61.0)
    assert lines == ["at the bound", "at the bound (59 more times since the last report)"]
    said = []
    chatter = Chatter(said.append, budget=3, interval=10.0)
    for i in range(10):
        chatter(f"bridging /t{i}", float(i) / 10)
    chatter("bridging /late", 11.0)
    assert said == ["bridging /t0", "bridging /t1", "bridging /t2",
                    "7 more lines about bridges for remote beacons were not written (at most 3 "
                    "every 10 s)", "bridging /late"]
