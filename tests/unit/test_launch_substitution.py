"""roslaunch substitution args as pure functions."""

from __future__ import annotations

import math
from pathlib import Path

import pytest

from minros.launch.substitution import (
    ArgError,
    SubstitutionContext,
    SubstitutionError,
    collect_args,
    convert_value,
    resolve_args,
)


def ctx(**kw) -> SubstitutionContext:
    kw.setdefault("env", {"HOME": "/home/u", "ROBOT": "pr2"})
    kw.setdefault("find", lambda pkg: Path(f"/pkgs/{pkg}") if pkg != "missing" else None)
    return SubstitutionContext(**kw)


def test_collect_args_scanner():
    assert collect_args("$(find a)/x $(arg b) plain $") == ["find a", "arg b"]
    assert collect_args("no subs") == []
    with pytest.raises(SubstitutionError, match="Dollar signs"):
        collect_args("$(arg $(arg x))")
    with pytest.raises(SubstitutionError, match="Invalid left parenthesis"):
        collect_args("$(arg (x))")


def test_env_optenv_find_arg_dirname():
    c = ctx(args={"n": "3"}, filename="/a/b/c.launch")
    assert resolve_args("$(env HOME)/x", c) == "/home/u/x"
    assert resolve_args("$(optenv NOPE)", c) == ""
    assert resolve_args("$(optenv NOPE default words here)", c) == "default words here"
    assert resolve_args("$(optenv ROBOT other)", c) == "pr2"
    assert resolve_args("$(find pkg)/launch/x.launch", c) == "/pkgs/pkg/launch/x.launch"
    assert resolve_args("n=$(arg n) n=$(arg n)", c) == "n=3 n=3"
    assert resolve_args("$(dirname)/y.yaml", c) == "/a/b/y.yaml"
    assert resolve_args("", c) == "" and resolve_args(None, c) is None


def test_find_runs_after_arg():
    c = ctx(args={"p": "mypkg"})
    with pytest.raises(SubstitutionError):  # nesting is not allowed, as in roslaunch
        resolve_args("$(find $(arg p))", c)
    assert resolve_args("$(find mypkg)/$(arg p)", c) == "/pkgs/mypkg/mypkg"


def test_errors_are_clear():
    c = ctx()
    with pytest.raises(SubstitutionError, match="environment variable NOPE is not set"):
        resolve_args("$(env NOPE)", c)
    with pytest.raises(ArgError) as err:
        resolve_args("$(arg undefined)", c)
    assert err.value.name == "undefined"
    with pytest.raises(SubstitutionError, match=r"Unknown substitution command \[bogus x\]"):
        resolve_args("$(bogus x)", c)
    with pytest.raises(SubstitutionError, match="package 'missing' not found"):
        resolve_args("$(find missing)", c)
    with pytest.raises(SubstitutionError, match="no file/directory information"):
        resolve_args("$(dirname)", c)
    with pytest.raises(SubstitutionError, match="only accepts one argument"):
        resolve_args("$(env A B)", c)


def test_anon_is_stable_within_a_launch_and_differs_between_ids():
    c = ctx()
    first = resolve_args("$(anon talker)", c)
    assert first.startswith("talker_") and first == resolve_args("$(anon talker)", c.child())
    assert resolve_args("$(anon listener)", c) != first


def test_eval():
    c = ctx(args={"radius": "2", "flag": "true", "name": "bob"}, filename="/d/f.launch")
    assert resolve_args("$(eval 2 * pi * radius)", c) == str(2 * math.pi * 2)
    assert resolve_args("$(eval arg('radius') + 1)", c) == "3"
    assert resolve_args("$(eval flag and true)", c) == "True"
    assert resolve_args("$(eval name + '_x')", c) == "bob_x"
    assert resolve_args("$(eval optenv('NOPE', 'd'))", c) == "d"
    assert resolve_args("$(eval env('ROBOT') == 'pr2')", c) == "True"
    assert resolve_args("$(eval dirname())", c) == "/d"
    assert resolve_args("$(eval round(sin(pi), 1))", c) == "0.0"
    assert resolve_args("$(eval len(name) + max(1, 2))", c) == "5"
    with pytest.raises(SubstitutionError, match="double underscore"):
        resolve_args("$(eval ().__class__)", c)
    with pytest.raises(SubstitutionError, match="NameError"):
        resolve_args("$(eval open('/etc/passwd'))", c)
    with pytest.raises(ArgError):
        resolve_args("$(eval arg('nope'))", c)


@pytest.mark.parametrize("text,type_,expected", [
    ("3", "auto", 3), ("-3", "auto", -3), ("1.5", "auto", 1.5), ("1e3", "auto", "1e3"),
    ("1_000", "auto", "1_000"), ("True", "auto", True), ("false", "auto", False), ("hi", "auto", "hi"),
    ("3", "str", "3"), ("3", "string", "3"), ("3", "int", 3), ("3", "double", 3.0),
    ("1", "bool", True), ("FALSE", "boolean", False), ("[1, 2]", "yaml", [1, 2]),
    ("{a: deg(180)}", "yaml", {"a": math.pi}),
])
def test_convert_value(text, type_, expected):
    value = convert_value(text, type_)
    assert value == expected and type(value) is type(expected)


def test_convert_value_errors():
    with pytest.raises(ValueError, match="is not a 'bool' type"):
        convert_value("maybe", "bool")
    with pytest.raises(ValueError, match="Unknown type 'float'"):
        convert_value("1", "float")
    with pytest.raises(ValueError):
        convert_value("x", "int")


def test_find_takes_the_path_after_it_as_roslaunch():
    c = ctx()
    c.find = lambda pkg: Path("/w") / pkg
    assert resolve_args("$(find a)$(find a)", c) == "/w/a//w/a"
    assert resolve_args(r"$(find a)\x\y.xml $(find a)/z", c) == "/w/a/x/y.xml /w/a/z"
    assert resolve_args("$(find a)/ rest", c) == "/w/a rest"
