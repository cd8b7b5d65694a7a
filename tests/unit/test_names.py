"""minros.names against rosgraph.names: hand-picked facts, properties, and a bulk oracle comparison."""

from __future__ import annotations

import json
import random
import subprocess

import pytest
from hypothesis import given
from hypothesis import strategies as st

from minros import names
from support import REFERENCE_PYTHON, reference_env, require_reference

name_text = st.text(alphabet="/~ab_1:", max_size=12)


@pytest.mark.parametrize("name, expected", [
    ("", ""), ("/", "/"), ("//", "/"), ("/a//b/", "/a/b"), ("a/b/", "a/b"), ("~a//b", "~a/b"),
])
def test_canonicalize(name, expected):
    assert names.canonicalize_name(name) == expected


@pytest.mark.parametrize("name, expected", [
    ("", "/"), ("/", "/"), ("/wg/node1", "/wg/"), ("/a/b/", "/a/"), ("node", "/"), ("a/b", "a/"),
])
def test_namespace(name, expected):
    assert names.namespace(name) == expected


def test_namespace_rejects_non_strings():
    with pytest.raises(ValueError):
        names.namespace(None)
    with pytest.raises(TypeError):
        names.namespace(3)


@pytest.mark.parametrize("name, caller, expected", [
    ("p", "/sub/node", "/sub/p"),
    ("~p", "/sub/node", "/sub/node/p"),
    ("/p", "/sub/node", "/p"),
    ("", "/sub/node", "/sub/"),
    ("a//b/", "/node", "/a/b"),
    ("~", "/sub/node", "/sub/node"),
])
def test_resolve_name(name, caller, expected):
    assert names.resolve_name(name, caller) == expected


def test_resolve_name_applies_remappings_to_resolved_names():
    remaps = names.resolve_mappings({"chatter": "/other", "__name": "n"}, "/ns/node")
    assert remaps == {"/ns/chatter": "/other", "__name": "n"}
    assert names.resolve_name("chatter", "/ns/node", remaps) == "/other"
    assert names.resolve_name("/chatter", "/ns/node", remaps) == "/chatter"


def test_ns_join():
    assert names.ns_join("/a", "b") == "/a/b"
    assert names.ns_join("/a/", "b") == "/a/b"
    assert names.ns_join("/a", "/b") == "/b"
    assert names.ns_join("/a", "~b") == "~b"
    assert names.ns_join("~", "b") == "~b"
    assert names.ns_join("", "b") == "b"


def test_legality():
    assert names.is_legal_name("") and names.is_legal_name("/a/b_1") and names.is_legal_name("~x")
    assert not names.is_legal_name("a//b") and not names.is_legal_name("1a")
    assert not names.is_legal_name("a b") and not names.is_legal_name(None)
    assert not names.is_legal_name("abc\n")
    assert names.is_legal_base_name("node_1") and not names.is_legal_base_name("a/b")
    assert not names.is_legal_base_name("") and not names.is_legal_base_name("_a")


def test_remapping_arguments():
    argv = ["prog", "chatter:=/x", "_rate:=10", "__name:=talker", "__ns:=/robot", "plain", "a:=b:=c",
            "1:=2", "_s:=[1, 2]"]
    assert names.load_mappings(argv) == {"chatter": "/x", "__name": "talker", "__ns": "/robot"}
    assert names.strip_remapping_args(argv) == ["prog", "plain", "1:=2"]
    assert names.load_command_line_node_params(["_rate:=10", "_x:=1.5", "_b:=true", "_s:=[1, 2]",
                                                 "__name:=n", "a:=b"]) == {
        "rate": 10, "x": 1.5, "b": True, "s": [1, 2]}
    with pytest.raises(ValueError):
        names.load_command_line_node_params(["_p:=[unclosed"])


def test_ros_namespace_and_caller_id():
    assert names.get_ros_namespace({}, []) == "/"
    assert names.get_ros_namespace({"ROS_NAMESPACE": "robot"}, []) == "/robot/"
    assert names.get_ros_namespace({"ROS_NAMESPACE": "robot"}, ["__ns:=other"]) == "/other/"
    assert names.make_caller_id("node", {"ROS_NAMESPACE": "/r"}, []) == "/r/node/"
    with pytest.raises(ValueError):
        names.make_global_ns("~x")


def test_anonymous_name_is_legal_and_unique():
    a, b = names.anonymous_name("rostopic"), names.anonymous_name("rostopic")
    assert a != b and a.startswith("rostopic_")
    assert names.is_legal_base_name(a)


@given(name_text)
def test_canonical_form_is_idempotent_and_slash_free_at_end(name):
    c = names.canonicalize_name(name)
    assert names.canonicalize_name(c) == c
    assert "//" not in c
    assert c in ("", "/") or not c.endswith("/")


@given(name_text, st.from_regex(r"\A(/[a-z]{1,3}){1,3}\Z"))
def test_resolved_names_are_global_and_canonical(name, caller):
    resolved = names.resolve_name(name, caller)
    assert resolved.startswith("/")
    if name:
        assert names.canonicalize_name(resolved) == resolved


# ---------------------------------------------------------------- the rosgraph.names oracle, in one batch

_ORACLE = r"""
import json, sys
import rosgraph.names as n
cases = json.load(sys.stdin)
out = []
def call(fn, *args):
    try:
        r = fn(*args)
        return ["ok", bool(r) if fn in (n.is_global, n.is_private) else r]
    except Exception as e:
        return ["err", type(e).__name__]
for kind, args in cases:
    if kind == "load_mappings":
        import io, contextlib
        with contextlib.redirect_stderr(io.StringIO()):
            out.append(call(n.load_mappings, args[0]))
    else:
        out.append(call(getattr(n, kind), *args))
print(json.dumps(out))
"""


def _ours(kind, args):
    try:
        return ["ok", getattr(names, kind)(*args)]
    except Exception as exc:  # noqa: BLE001 - comparing exception types with the oracle
        return ["err", type(exc).__name__]


def _cases():
    rng = random.Random(20261121)
    alphabet = "/~ab_1: é\n"
    def word():
        return "".join(rng.choice(alphabet) for _ in range(rng.randint(0, 8)))
    callers = ["/", "/node", "/a/b/node", "/a/", "", "node", "a/b"]
    cases = []
    for _ in range(1500):
        w = word()
        cases.append(["canonicalize_name", [w]])
        cases.append(["namespace", [w]])
        cases.append(["is_legal_name", [w]])
        cases.append(["is_legal_base_name", [w]])
        cases.append(["is_global", [w]])
        cases.append(["is_private", [w]])
        cases.append(["ns_join", [rng.choice(callers + ["~"]), w]])
        cases.append(["resolve_name", [w, rng.choice(callers)]])
        cases.append(["resolve_name", [w, word()]])
        remap = word() + ":=" + word() + rng.choice(["", ":=" + word(), "\nx"])
        cases.append(["is_legal_remap", [remap]])
        cases.append(["load_mappings", [[remap, word()]]])
    return cases


@pytest.mark.slow
def test_matches_rosgraph_names_oracle():
    require_reference()
    cases = _cases()
    proc = subprocess.run([REFERENCE_PYTHON, "-c", _ORACLE], input=json.dumps(cases), text=True,
                          capture_output=True, env=reference_env({}), timeout=60)
    assert proc.returncode == 0, proc.stderr
    expected = json.loads(proc.stdout)
    mismatches = []
    for (kind, args), exp in zip(cases, expected):
        got = _ours(kind, args)
        if got != exp:
            mismatches.append((kind, args, exp, got))
    assert not mismatches, mismatches[:10]
    assert len(expected) == len(cases)
