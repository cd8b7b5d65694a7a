"""Parameters compared with Debian's rospy: the same script, run as a node by both
implementations on Debian's rosmaster, gets the same values and the same errors."""

from __future__ import annotations

import json
import subprocess
from pathlib import Path

import pytest

from support import PYTHON, REFERENCE_PYTHON, reference_env, require_reference, ros_env

pytestmark = pytest.mark.interop

SCRIPT = r'''
import json
import sys
import rospy

rospy.init_node("pnode")
res = {}
def rec(key, fn):
    try:
        res[key] = fn()
    except Exception as e:
        res[key] = "%s %s" % (type(e).__name__, e)

rec("get_missing", lambda: rospy.get_param("missing"))
rec("get_default", lambda: rospy.get_param("missing", 5))
rec("private", lambda: rospy.get_param("~p"))
rec("remapped", lambda: rospy.get_param("alias"))
rospy.set_param("tree", {"a": 1, "b": {"c": [1, 2.5, "x", True]}})
rec("tree", lambda: rospy.get_param("tree"))
rec("tree_leaf", lambda: rospy.get_param(rospy.get_namespace() + "tree/b/c"))
rospy.set_param("tree", {"z": 0})
rec("tree_replaced", lambda: rospy.get_param("tree"))
rec("has", lambda: [rospy.has_param(x) for x in ("tree", "tree/z", "tree/", "nope", "~p")])
rec("delete_missing", lambda: rospy.delete_param("nope"))
rec("delete", lambda: rospy.delete_param("tree/z"))
rec("after_delete", lambda: rospy.get_param("tree"))
rec("search", lambda: [rospy.search_param(x) for x in ("p", "tree", "nothing")])
rec("names", lambda: sorted(n for n in rospy.get_param_names()
                            if n.startswith(rospy.get_namespace())))
rospy.set_param("cached", 1)
rec("cached1", lambda: rospy.get_param_cached("cached"))
rospy.set_param("cached", 2)  # rospy's set_param also refreshes its own cache
rec("cached2", lambda: rospy.get_param_cached("cached"))
rec("cached_missing", lambda: rospy.get_param_cached("nope_cached"))
rec("cached_default", lambda: rospy.get_param_cached("nope_cached", "d"))
rec("big_int", lambda: (rospy.set_param("big", 2**31 - 1), rospy.get_param("big"))[1])
rec("unicode", lambda: (rospy.set_param("u", "h\u00e9llo \u2603"), rospy.get_param("u"))[1])
print("RESULT " + json.dumps(res, sort_keys=True), flush=True)
'''


def test_params_match_rospy(tmp_path: Path, debian_rosmaster: int, ros_home: Path):
    require_reference()
    script = tmp_path / "params_script.py"
    script.write_text(SCRIPT)
    env = ros_env(debian_rosmaster, ros_home)
    subprocess.run(["/usr/bin/rosparam", "set", "/ref/target", "42"], env=reference_env(env),
                   check=True, timeout=30, capture_output=True)
    subprocess.run(["/usr/bin/rosparam", "set", "/our/target", "42"], env=reference_env(env),
                   check=True, timeout=30, capture_output=True)
    results = {}
    for impl, python, penv in (("ref", REFERENCE_PYTHON, reference_env(env)), ("our", PYTHON, env)):
        done = subprocess.run([python, str(script), f"__ns:=/{impl}", "_p:=3", "alias:=target"],
                              env=penv, capture_output=True, text=True, timeout=60)
        assert done.returncode == 0, done.stderr
        line = next(x for x in done.stdout.splitlines() if x.startswith("RESULT "))
        results[impl] = json.loads(line[7:].replace(f"/{impl}/", "/NS/"))
    ref = results["ref"]
    assert ref["private"] == 3 and ref["remapped"] == 42 and ref["get_missing"] == "KeyError 'missing'"
    assert results["our"] == ref
