"""actionlib: a Debian (ROS 1) action client drives a minros action server and the other way
round, through goal, feedback, result, cancel-preemption, newer-goal preemption, rejection,
recall of a pending goal, a cancel of a finished goal and a goal for a server nobody runs.
The client state table is checked against ROS 1's entry by entry."""

from __future__ import annotations

import json
import subprocess
from pathlib import Path

import pytest

from interop.actionlib_scripts import CLIENT, EXPECTED, SERVER
from support import PYTHON, REFERENCE_PYTHON, Proc, reference_env, require_reference, ros_env

pytestmark = pytest.mark.interop


def _proc(impl: str, script: Path, port: int, home: Path) -> Proc:
    env = ros_env(port, home)
    if impl == "rospy":
        return Proc([REFERENCE_PYTHON, str(script)], reference_env(env))
    return Proc([PYTHON, str(script)], env)


@pytest.mark.parametrize("server_impl, client_impl", [("minros", "rospy"), ("rospy", "minros")])
def test_clients_and_servers_drive_each_other(tmp_path: Path, debian_rosmaster: int, ros_home: Path,
                                              server_impl: str, client_impl: str) -> None:
    server_script = tmp_path / "server.py"
    client_script = tmp_path / "client.py"
    server_script.write_text(SERVER)
    client_script.write_text(CLIENT)
    server = _proc(server_impl, server_script, debian_rosmaster, ros_home)
    client = None
    try:
        server.read_until("server ready", 30)
        client = _proc(client_impl, client_script, debian_rosmaster, ros_home)
        out = client.read_until("client done", 90)
        lines = [line for line in out.splitlines() if not line.startswith("[")]
        assert lines == EXPECTED, out
        # the server's user never saw an error (the finished goal's cancel changed nothing)
        server_out = server.stop()
        assert "ERROR" not in server_out and "Traceback" not in server_out, server_out
    finally:
        if client is not None:
            client.stop()
        server.stop()


DUMP_TABLE = r'''
import json
from actionlib.action_client import _transitions, NO_TRANSITION, INVALID_TRANSITION
out = {}
for state, row in _transitions.items():
    for status, step in row.items():
        if step == NO_TRANSITION:
            steps = []
        elif step == INVALID_TRANSITION:
            steps = ["invalid"]
        elif isinstance(step, tuple):
            steps = list(step)
        else:
            steps = [step]
        out["%d,%d" % (state, status)] = steps
print(json.dumps(out, sort_keys=True))
'''


def test_client_state_table_equals_ros1() -> None:
    require_reference()
    done = subprocess.run([REFERENCE_PYTHON, "-c", DUMP_TABLE], env=reference_env({}),
                          capture_output=True, text=True, timeout=60)
    assert done.returncode == 0, done.stderr
    reference = json.loads(done.stdout)
    from minros.actionlib.states import COMM_TRANSITIONS, INVALID_TRANSITION

    ours = {}
    for state, row in COMM_TRANSITIONS.items():
        for status, steps in row.items():
            ours[f"{state},{status}"] = ["invalid"] if steps == (INVALID_TRANSITION,) else list(steps)
    assert ours == reference
