"""minros services <-> Debian's rospy and rosservice, on Debian's rosmaster.

The same server and client scripts run on both implementations; Debian's pair is the oracle,
so every answer and every error text of the minros combinations must equal its answer.
"""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from services_support import CLIENT, SERVER, make_reference_modules
from support import (
    EXAMPLES,
    PYTHON,
    REFERENCE_PYTHON,
    Proc,
    reference_env,
    require_reference,
    ros_env,
)

pytestmark = pytest.mark.interop

SCRIPTS = EXAMPLES / "add_two_ints"


@pytest.fixture
def env_for(tmp_path: Path, debian_rosmaster: int, ros_home: Path):
    """``env_for(impl)`` -> (python, environment) for a node of ``impl`` on the master."""
    require_reference()
    deb_path = make_reference_modules(tmp_path)

    def make(impl: str):
        env = ros_env(debian_rosmaster, ros_home)
        if impl == "rospy":
            env = reference_env(env)
            env["PYTHONPATH"] = deb_path
            return REFERENCE_PYTHON, env
        return PYTHON, env

    return make


@pytest.fixture
def scripts(tmp_path: Path):
    server = tmp_path / "server.py"
    client = tmp_path / "client.py"
    server.write_text(SERVER)
    client.write_text(CLIENT)
    return server, client


def run_client(env_for, client: Path, impl: str, service: str) -> dict:
    python, env = env_for(impl)
    proc = Proc([python, str(client), service], env)
    try:
        out = proc.read_until("RESULT ", 40)
    finally:
        rest = proc.stop()
    line = next(x for x in (out + rest).splitlines() if x.startswith("RESULT "))
    return json.loads(line[len("RESULT "):])


def normalise(result: dict, service: str) -> dict:
    return json.loads(json.dumps(result).replace(service, "<srv>"))


def test_same_answers_and_error_texts_in_all_four_combinations(env_for, scripts):
    server, client = scripts
    servers = {}
    try:
        for impl in ("rospy", "minros"):
            python, env = env_for(impl)
            servers[impl] = Proc([python, str(server), f"adder_{impl}", f"__ns:=/{impl}"], env)
        for proc in servers.values():
            proc.read_until("READY", 30)
        results = {}
        for server_impl in ("rospy", "minros"):
            for client_impl in ("rospy", "minros"):
                service = f"/{server_impl}/add_two_ints"
                results[server_impl, client_impl] = normalise(
                    run_client(env_for, client, client_impl, service), service)
    finally:
        outputs = {impl: proc.stop() for impl, proc in servers.items()}

    oracle = results["rospy", "rospy"]
    # the oracle itself, so a broken reference setup cannot make everything trivially equal
    assert oracle["20"] == 21 and oracle["16"] == 17 and oracle["17"] == 18 and oracle["18"] == 19
    assert oracle["13"] == ("ERR service [<srv>] responded with an error: "
                            "b'service cannot process request: unlucky number'")
    assert oracle["14"] == "ERR service [<srv>] responded with an error: b'error processing request: boom'"
    assert oracle["bad"].startswith("ERR unable to connect to service: remote error reported: "
                                    "request from [/unnamed]: md5sums do not match:")
    for combo, result in results.items():
        # a tuple of the wrong arity: the wording after the prefix is the message class's own
        wrong_arity = result.pop("19")
        assert wrong_arity.startswith("ERR service [<srv>] responded with an error: b"), combo
        assert ("service cannot process request: handler returned wrong number of values: "
                in wrong_arity), combo
        if combo != ("rospy", "rospy"):
            assert result == {k: v for k, v in oracle.items() if k != "19"}, combo
    assert oracle["cookies"] == len("chocolate")
    # the server side of an md5 mismatch: the same warning (after the timestamp) from both
    warnings = {}
    for impl, out in outputs.items():
        warnings[impl] = sorted(line.split("]: ", 1)[1] for line in out.splitlines()
                                if "Could not process inbound connection" in line)
    assert len(warnings["rospy"]) == 2  # one per client implementation
    expected = [w.replace("/rospy/", "/minros/") for w in warnings["rospy"]]
    assert warnings["minros"] == expected
    assert expected[0].startswith("Could not process inbound connection: request from [/unnamed]: "
                                  "md5sums do not match: [60962375a49bd6746d7c85dff75ebb9c] vs. "
                                  "[6a2e34150c00229791cc89ff309fff21]{")
    assert "error handler saw boom" in outputs["minros"]
    assert "Returning [20 + 1 = 21]" in outputs["minros"]


def test_debian_rosservice_against_minros_tutorial_server(env_for, monkeypatch):
    import minros

    python, env = env_for("minros")
    monkeypatch.setenv("ROS_MASTER_URI", env["ROS_MASTER_URI"])
    server = Proc([python, str(SCRIPTS / "add_two_ints_server.py")], env)
    _, ref = env_for("rospy")
    try:
        import subprocess

        def rosservice(*args: str) -> str:
            done = subprocess.run(["/usr/bin/rosservice", *args], env=ref, capture_output=True,
                                  text=True, timeout=30)
            assert done.returncode == 0, done.stderr
            return done.stdout

        # the tutorial server prints nothing when ready: wait for its last service instead
        minros.wait_for_service("/add_two_ints", timeout=20)
        minros.wait_for_service("/add_two_ints_server/set_logger_level", timeout=20)
        assert rosservice("list").split() == ["/add_two_ints", "/add_two_ints_server/get_loggers",
                                              "/add_two_ints_server/set_logger_level"]
        assert rosservice("call", "/add_two_ints", "7", "8").strip() == "sum: 15"
        info = rosservice("info", "/add_two_ints")
        assert "Node: /add_two_ints_server" in info
        assert "Type: rospy_tutorials/AddTwoInts" in info and "Args: a b" in info
        assert rosservice("type", "/add_two_ints").strip() == "rospy_tutorials/AddTwoInts"
        loggers = rosservice("call", "/add_two_ints_server/get_loggers")
        assert 'name: "rosout"' in loggers
        rosservice("call", "/add_two_ints_server/set_logger_level", "rosout", "error")
        loggers = rosservice("call", "/add_two_ints_server/get_loggers")
        chunk = loggers.split('name: "rosout"', 1)[1]
        assert chunk.split("level:", 1)[1].split()[0] == '"error"'
    finally:
        out = server.stop()
    assert "Returning [7 + 8 = 15]" in out


@pytest.mark.smoke
def test_tutorial_client_on_minros_against_rospy_server(env_for, scripts):
    server, _ = scripts
    python, env = env_for("rospy")
    srv = Proc([python, str(server), "add_two_ints_server"], env)
    try:
        srv.read_until("READY", 30)
        mpython, menv = env_for("minros")
        client = Proc([mpython, str(SCRIPTS / "add_two_ints_client.py"), "40", "2"], menv)
        out = client.read_until("40 + 2 = 42", 30)
        client.stop()
        assert "Requesting 40+2" in out
    finally:
        srv_out = srv.stop()
    assert srv_out.count("Returning [40 + 2 = 42]") == 2  # simplified and formal call styles
