"""Parameters from nodes on minros's master: rospy semantics of get/set/has/delete/search,
private (~) and remapped names, and get_param_cached kept fresh by paramUpdate."""

from __future__ import annotations

import json
import xmlrpc.client
from pathlib import Path

import pytest

import minros
from minros.client import params
from support import PYTHON, Proc, ros_env


@pytest.fixture
def master_env(minros_master: int, ros_home: Path, monkeypatch):
    env = ros_env(minros_master, ros_home)
    monkeypatch.setenv("ROS_MASTER_URI", env["ROS_MASTER_URI"])
    params._cache.clear()
    yield env
    params._cache.clear()


def master(env):
    return xmlrpc.client.ServerProxy(env["ROS_MASTER_URI"])


@pytest.mark.smoke
def test_set_get_has_delete_without_a_node(master_env):
    minros.set_param("/test/int", 5)
    minros.set_param("test/float", 1.5)  # relative to /unnamed -> /test/float
    minros.set_param("/test/list", [1, "two", 3.0, True])
    minros.set_param("/test/dict", {"a": 1, "b": {"c": "d"}})
    assert minros.get_param("/test/int") == 5
    assert minros.get_param("/test/float") == 1.5
    assert minros.get_param("/test/list") == [1, "two", 3.0, True]
    assert minros.get_param("/test/dict/b/c") == "d"
    assert minros.get_param("/test") == {"int": 5, "float": 1.5, "list": [1, "two", 3.0, True],
                                         "dict": {"a": 1, "b": {"c": "d"}}}
    # a dict replaces the whole namespace
    minros.set_param("/test/dict", {"z": 0})
    assert minros.get_param("/test/dict") == {"z": 0}
    assert minros.has_param("/test/int") and minros.has_param("/test") and minros.has_param("/test/")
    assert not minros.has_param("/test/nope")
    with pytest.raises(KeyError) as info:
        minros.get_param("/test/nope")
    assert info.value.args == ("/test/nope",)
    assert minros.get_param("/test/nope", "fallback") == "fallback"
    assert minros.get_param("/test/nope", None) is None
    minros.delete_param("/test/int")
    assert not minros.has_param("/test/int")
    with pytest.raises(KeyError) as info:
        minros.delete_param("/test/int")
    assert info.value.args == ("/test/int",)
    names = minros.get_param_names()
    assert "/test/float" in names and "/test/dict/z" in names and "/test/int" not in names


def test_search_param(master_env):
    minros.set_param("/a/b/gain", 3)
    minros.set_param("/gain", 1)
    assert minros.search_param("gain") == "/gain"  # from /unnamed: only the root namespace
    assert minros.search_param("nothing_like_it") is None


NODE = r'''
import json, time, sys
import rospy
from minros import node as N

rospy.init_node("pnode")
out = {
    "private": rospy.get_param("~private"),
    "relative": rospy.get_param("rel"),
    "remapped": rospy.get_param("gain"),
    "search": rospy.search_param("deep"),
    "has_private": rospy.has_param("~private"),
}
rospy.set_param("~written", [1, 2])
rospy.set_param("relative_written", "yes")
out["cached1"] = rospy.get_param_cached("/watched")
out["cached_missing"] = rospy.get_param_cached("/not_there", "dflt")
calls = []
original = N.master().raw
def counting(method, *args):
    calls.append(method)
    return original(method, *args)
N.master().raw = counting
print("RESULT1 " + json.dumps(out), flush=True)
deadline = time.monotonic() + 20
value = out["cached1"]
while time.monotonic() < deadline and value == out["cached1"]:
    value = rospy.get_param_cached("/watched")
    time.sleep(0.01)
print("RESULT2 " + json.dumps({"cached2": value, "master_calls": calls}), flush=True)
rospy.spin()
'''


def result(proc: Proc, tag: str) -> dict:
    out = proc.read_until(tag, 30)
    line = next(x for x in out.splitlines() if x.startswith(tag))
    return json.loads(line[len(tag) + 1:])


def test_node_private_relative_remapped_and_cached(master_env, tmp_path):
    m = master(master_env)
    m.setParam("/test", "/ns/rel", "relative value")
    m.setParam("/test", "/global_gain", 2.5)
    m.setParam("/test", "/ns/deep", "found")
    m.setParam("/test", "/watched", 1)
    script = tmp_path / "pnode.py"
    script.write_text(NODE)
    proc = Proc([PYTHON, str(script), "__ns:=/ns", "_private:=7", "gain:=/global_gain"], master_env)
    try:
        first = result(proc, "RESULT1")
        assert first == {"private": 7, "relative": "relative value", "remapped": 2.5,
                         "search": "/ns/deep", "has_private": True, "cached1": 1,
                         "cached_missing": "dflt"}
        code, _msg, value = m.getParam("/test", "/ns/pnode/written")
        assert (code, value) == (1, [1, 2])
        code, _msg, value = m.getParam("/test", "/ns/relative_written")
        assert (code, value) == (1, "yes")
        # another process changes the parameter: the master's paramUpdate refreshes the cache
        minros.set_param("/watched", {"now": "a dict"})
        second = result(proc, "RESULT2")
        assert second == {"cached2": {"now": "a dict"}, "master_calls": []}
    finally:
        proc.stop()


UNSET_NODE = r'''
import json, time
import rospy
from minros import node

rospy.init_node("unset_node")
calls = []
me = node.default_node()
original = me.master.raw
def counting(method, *args):
    calls.append(method)
    return original(method, *args)
me.master.raw = counting
first = [rospy.get_param_cached("/later", "dflt") for _ in range(5)]
print("RESULT1 " + json.dumps({"values": first, "master_calls": calls}), flush=True)
deadline = time.monotonic() + 20
value = "dflt"
while time.monotonic() < deadline and value == "dflt":
    value = rospy.get_param_cached("/later", "dflt")
    time.sleep(0.01)
print("RESULT2 " + json.dumps({"value": value}), flush=True)
rospy.spin()
'''


def test_cached_unset_parameter_asks_the_master_once(master_env, tmp_path):
    """rospy asks the master again on every get_param_cached of an unset key (the log's
    /rosout_disable_topics_generation on every log line); minros subscribes once and waits
    for the master's paramUpdate, which arrives when someone sets the key."""
    script = tmp_path / "unset_node.py"
    script.write_text(UNSET_NODE)
    proc = Proc([PYTHON, str(script)], master_env)
    try:
        first = result(proc, "RESULT1")
        assert first == {"values": ["dflt"] * 5, "master_calls": ["subscribeParam"]}
        minros.set_param("/later", 42)
        assert result(proc, "RESULT2") == {"value": 42}
    finally:
        proc.stop()
