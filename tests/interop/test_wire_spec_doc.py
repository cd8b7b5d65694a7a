"""docs/wire.md states the wire protocol from real traces of minros, Debian's rospy and a
roscpp node: scripts/wire_spec_traces.py reruns the scenario and the page must agree with this
run (ports, pids, times and counts aside), and every call its tables describe must be in an
excerpt."""

from __future__ import annotations

import importlib.util
import shutil
import subprocess

import pytest

from support import PYTHON, REPO, need, require_reference

SCRIPT = REPO / "scripts" / "wire_spec_traces.py"

pytestmark = pytest.mark.interop


def _script():
    spec = importlib.util.spec_from_file_location("wire_spec_traces", SCRIPT)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def test_the_comparison_ignores_only_what_changes_between_runs():
    normalize = _script().wire_normalize
    one = ('getPid("/api_probe")\n    <- 1, "", 3362\n'
           'getBusInfo("/api_probe")\n    <- 1, "bus info", [[N, "/cpp_node", "o", "TCPROS", '
           '"/chatter", true, "TCPROS connection on port 41571 to [127.0.0.1:40238 on socket 17]"'
           '\nto /cpp_node (roscpp): requestTopic("/api_probe", "/no_such_topic", [["TCPROS"]])'
           '\n    <- 1, "", ["TCPROS", "localhost", 58133]')
    other = (one.replace("3362", "991").replace("41571", "1234").replace("40238", "5")
             .replace("socket 17", "socket 9").replace("58133", "40000"))
    assert normalize(one) == normalize(other)
    assert normalize(one) != normalize(one.replace('"TCPROS", "localhost"', '"UDPROS", "x"'))
    assert normalize(one) != normalize(one.replace("<- 1,", "<- 0,"))


def test_the_page_agrees_with_a_fresh_run():
    require_reference()
    need(shutil.which("g++") is not None and shutil.which("pkg-config") is not None,
         "g++ and pkg-config build the roscpp node", "scripts/install-ros-reference.sh")
    done = subprocess.run([PYTHON, str(SCRIPT), "--check"], capture_output=True, text=True,
                          timeout=400)
    assert done.returncode == 0, done.stdout + done.stderr
    assert "14 excerpts agree with this run" in done.stdout
