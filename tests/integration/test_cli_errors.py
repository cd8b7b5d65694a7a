"""Bad input to the command-line tools: one line on stderr, the real tool's exit status,
never a traceback or a hang (no master, a master that never answers, unknown names and
types, malformed YAML, wrong field names and types, dead nodes)."""

from __future__ import annotations

import socket
import subprocess
import time
import xmlrpc.client
from pathlib import Path

import pytest

from support import PYTHON, Proc, free_port, ros_env, wait_for_master

DEMO = str(Path(__file__).resolve().parent / "cli_demo_node.py")
BIN = Path(PYTHON).parent


def run(tool: str, *args: str, env: dict, stdin: str | None = None, timeout: float = 20) -> subprocess.CompletedProcess:
    start = time.monotonic()
    done = subprocess.run([str(BIN / tool), *args], env=env, input=stdin if stdin is not None else "",
                          capture_output=True, text=True, timeout=timeout)
    done.elapsed = time.monotonic() - start  # type: ignore[attr-defined]
    return done


def assert_one_line_error(done: subprocess.CompletedProcess, status: int, *needles: str) -> None:
    lines = done.stderr.strip().splitlines()
    assert done.returncode == status, (done.returncode, done.stdout, done.stderr)
    assert "Traceback" not in done.stderr, done.stderr
    assert len(lines) == 1, done.stderr
    for needle in needles:
        assert needle in lines[0], done.stderr


# ---------------------------------------------------------------------------------------------
# no master / a master that never answers

NO_MASTER = [
    ("rostopic", ["list"], 1), ("rostopic", ["info", "/x"], 1), ("rostopic", ["type", "/x"], 1),
    ("rostopic", ["find", "std_msgs/String"], 1), ("rostopic", ["echo", "/x"], 1),
    ("rostopic", ["hz", "/x"], 1), ("rostopic", ["bw", "/x"], 1), ("rostopic", ["delay", "/x"], 1),
    ("rostopic", ["pub", "/x", "std_msgs/String", "hi"], 1),
    ("rosnode", ["list"], 1), ("rosnode", ["info", "/x"], 1), ("rosnode", ["ping", "/x"], 1),
    ("rosnode", ["kill", "/x"], 1), ("rosnode", ["machine"], 1), ("rosnode", ["cleanup"], 1),
    ("rosparam", ["list"], 1), ("rosparam", ["get", "/x"], 1), ("rosparam", ["set", "/x", "1"], 1),
    ("rosparam", ["dump"], 1), ("rosparam", ["delete", "/x"], 1),
    ("rosservice", ["list"], 2), ("rosservice", ["call", "/x"], 2), ("rosservice", ["type", "/x"], 2),
    ("rosservice", ["info", "/x"], 2), ("rosservice", ["uri", "/x"], 2), ("rosservice", ["args", "/x"], 2),
    ("rosservice", ["find", "std_srvs/Empty"], 2),
    ("minros", ["graph"], 1),
]


@pytest.mark.parametrize("tool,args,status", NO_MASTER, ids=[f"{t} {' '.join(a)}" for t, a, _ in NO_MASTER])
def test_no_master(tool: str, args: list, status: int, tmp_path: Path) -> None:
    env = ros_env(free_port(), tmp_path)  # nothing listens there
    done = run(tool, *args, env=env)
    assert_one_line_error(done, status, "ERROR: Unable to communicate with master!")


def test_silent_master_times_out(tmp_path: Path) -> None:
    """A master that accepts connections but never answers: bounded wait, then one line."""
    with socket.socket() as server:
        server.bind(("127.0.0.1", 0))
        server.listen(16)
        env = ros_env(server.getsockname()[1], tmp_path)
        done = run("rostopic", "list", env=env, timeout=30)
    assert_one_line_error(done, 1, "ERROR: Unable to communicate with master!")
    assert done.elapsed < 15  # type: ignore[attr-defined]


# ---------------------------------------------------------------------------------------------
# with a master

@pytest.fixture(scope="module")
def graph(tmp_path_factory):
    home = tmp_path_factory.mktemp("cli_errors")
    (home / "log").mkdir()
    port = free_port()
    env = ros_env(port, home)
    master = Proc([PYTHON, "-m", "minros.master", "-p", str(port)], env)
    node = None
    try:
        wait_for_master(port)
        node = Proc([PYTHON, DEMO, "demo"], env)
        node.read_until("ready", 30)
        yield env
    finally:
        if node is not None:
            node.stop()
        master.stop()


@pytest.mark.parametrize("args,status,needles", [
    (["get", "/nope"], 1, ["ERROR: Parameter [/nope] is not set"]),
    (["delete", "/nope"], 1, ["ERROR: parameter [/nope] is not set"]),
    (["set", "/x", "{bad"], 1, ["ERROR: invalid YAML"]),
    (["set", "/x", "99999999999"], 1, ["32-bit"]),
    (["set", "/x", "deg(abc)"], 1, ["ERROR:", "degree"]),
    (["load", "/nonexistent.yaml"], 1, ["ERROR: file [/nonexistent.yaml] does not exist"]),
    (["load", "-", "/ns"], 1, ["ERROR: invalid YAML"]),
    (["get"], 2, ["error: invalid arguments. Please specify a parameter name"]),
])
def test_param_bad_input(graph: dict, args: list, status: int, needles: list) -> None:
    done = run("rosparam", *args, env=graph, stdin="a: [1, 2\n" if args[0] == "load" else None)
    assert_one_line_error(done, status, *needles) if status != 2 else None
    assert done.returncode == status
    assert "Traceback" not in done.stderr
    for needle in needles:
        assert needle in done.stderr


@pytest.mark.parametrize("args,needles", [
    (["pub", "/x", "nope/Nope", "1"], ["ERROR: invalid message type: nope/Nope"]),
    (["pub", "/x", "std_msgs/String", "{nope: 1}"], ["No field name [nope]"]),
    (["pub", "/x", "std_msgs/String", "[1, 2]"], ["ERROR:", "str"]),
    (["pub", "/x", "geometry_msgs/Point", "1", "2"], ["Not enough arguments"]),
    (["pub", "/x", "geometry_msgs/Point", "1", "2", "3", "4"], ["Too many arguments"]),
    (["pub", "/x", "std_msgs/Int8", "300"], ["ERROR:", "Unable to publish message"]),
    (["pub", "/x", "std_msgs/Header", "{stamp: yesterday}"], ["No key named [yesterday]"]),
    (["pub", "/x", "std_msgs/Int32MultiArray", "{data: 3}"], ["must be a list or tuple"]),
    (["info", "/nope"], ["ERROR: Unknown topic /nope"]),
    (["type", "/nope"], ["unknown topic type [/nope]"]),
    (["echo", "--filter", "m.data ==", "/demo_chatter"], ["ERROR: invalid filter expression"]),
    (["echo", "/pose/pose/nope"], ["ERROR: no field named [pose/nope] in topic [/pose]"]),
    (["hz", "/demo_chatter/text"], ["ERROR: no field named [text]"]),
])
def test_topic_bad_input(graph: dict, args: list, needles: list) -> None:
    done = run("rostopic", *args, env=graph)
    assert_one_line_error(done, 1, *needles)


def test_pub_yaml_syntax_error_is_a_usage_error(graph: dict) -> None:
    done = run("rostopic", "pub", "/x", "std_msgs/String", "{a: [", env=graph)
    assert done.returncode == 2 and "Argument error" in done.stderr and "Traceback" not in done.stderr


@pytest.mark.parametrize("args,status,needles", [
    (["call", "/nope"], 2, ["ERROR: Service [/nope] is not available."]),
    (["call", "/demo/set_bool", "{nope: 1}"], 2, ["ERROR: Incompatible arguments", "No field name [nope]"]),
    (["call", "/demo/set_bool", "1", "2"], 2, ["ERROR: Incompatible arguments", "Too many arguments"]),
    (["call", "/demo/set_bool", "[abc]"], 2, ["ERROR:", "incorrect type"]),
    (["type", "/nope"], 1, ["Unknown service [/nope]"]),
    (["uri", "/nope"], 1, ["Unknown service: /nope"]),
    (["info", "/nope"], 1, ["ERROR: unknown service"]),
    (["args", "/nope"], 2, ["ERROR: Service [/nope] is not available."]),
])
def test_service_bad_input(graph: dict, args: list, status: int, needles: list) -> None:
    done = run("rosservice", *args, env=graph)
    assert_one_line_error(done, status, *needles)


def _register_dead_node(env: dict) -> str:
    """A registration whose node is gone (its XML-RPC port is closed)."""
    master = xmlrpc.client.ServerProxy(env["ROS_MASTER_URI"])
    uri = f"http://localhost:{free_port()}/"
    code, msg, _ = master.registerPublisher("/ghost", "/ghost_topic", "std_msgs/String", uri)
    assert code == 1, msg
    return uri


def test_node_dead_and_unknown(graph: dict) -> None:
    uri = _register_dead_node(graph)
    done = run("rosnode", "kill", "/nope", env=graph)
    assert_one_line_error(done, 1, "ERROR: Unknown node(s)", "/nope")
    done = run("rosnode", "ping", "-c", "1", "/ghost", env=graph)
    assert done.returncode == 0  # as Debian's rosnode: the failure is reported, not the status
    assert done.stderr.strip() == f"ERROR: connection refused to [{uri}]"
    done = run("rosnode", "info", "/ghost", env=graph)
    assert_one_line_error(done, 1, f"ERROR: Communication with node[{uri}] failed!")
    assert "Publications: \n * /ghost_topic [std_msgs/String]" in done.stdout
    done = run("rosnode", "cleanup", env=graph, stdin="y\n")
    assert done.returncode == 0, done.stderr
    assert "Unable to contact the following nodes:\n * /ghost\n" in done.stdout
    assert done.stdout.rstrip().endswith("Unregistering /ghost\ndone")
    assert "/ghost" not in run("rosnode", "list", env=graph).stdout
    assert "/demo" in run("rosnode", "list", env=graph).stdout


def test_usage_and_help(graph: dict) -> None:
    for tool, status in (("rostopic", 64), ("rosnode", 64), ("rosservice", 64), ("rosparam", 0)):
        done = run(tool, env=graph)
        assert done.returncode == status and "Commands:" in done.stdout
        done = run(tool, "list", "--help", env=graph)
        assert done.returncode == 0 and "usage:" in done.stdout.lower()  # rosnode: "Usage:"
    done = run("minros", "graph", "-o", "/tmp/x.bmp", env=graph)
    assert_one_line_error(done, 1, "cannot tell the format")


# ---------------------------------------------------------------------------------------------
# what the master (or something in its place) answers, and parameter files: one line each

def _deep_reply(levels: int) -> bytes:
    return (b"<?xml version='1.0'?><methodResponse><params><param><value>"
            + b"<array><data><value>" * levels + b"<int>1</int>" + b"</value></data></array>" * levels
            + b"</value></param></params></methodResponse>")


BAD_REPLIES = {
    "garbage": (b"garbage \x00\xff", "(syntax error: line 1, column 0)"),
    "dtd": (b'<?xml version="1.0"?><!DOCTYPE m [<!ENTITY a "b">]><methodResponse><params><param>'
            b"<value>&a;</value></param></params></methodResponse>",
            "(XML document type declarations and entities are not allowed)"),
    "deep": (_deep_reply(100_000), "(arrays and structs nested more than 200 deep)"),
}


@pytest.fixture(scope="module")
def bad_masters():
    """``{kind: port}``: HTTP servers answering every call with ``BAD_REPLIES[kind]``."""
    import threading

    stop = threading.Event()
    listeners, threads = {}, []

    def serve(conn: socket.socket, body: bytes) -> None:
        with conn:
            conn.settimeout(5)
            conn.recv(65536)
            conn.sendall(b"HTTP/1.1 200 OK\r\nContent-Type: text/xml\r\nContent-Length: %d\r\n\r\n"
                         % len(body) + body)

    def accept(listener: socket.socket, body: bytes) -> None:
        while not stop.is_set():
            try:
                conn, _ = listener.accept()
            except socket.timeout:
                continue
            threading.Thread(target=serve, args=(conn, body), daemon=True).start()

    for kind, (body, _reason) in BAD_REPLIES.items():
        listener = socket.create_server(("127.0.0.1", 0))
        listener.settimeout(0.2)
        listeners[kind] = listener
        threads.append(threading.Thread(target=accept, args=(listener, body), daemon=True))
        threads[-1].start()
    yield {kind: listener.getsockname()[1] for kind, listener in listeners.items()}
    stop.set()
    for thread in threads:
        thread.join(5)
    for listener in listeners.values():
        listener.close()


@pytest.mark.parametrize("kind", sorted(BAD_REPLIES))
@pytest.mark.parametrize("tool,args", [("rosnode", ["list"]), ("rosparam", ["get", "/x"])])
def test_a_reply_that_is_not_xmlrpc(bad_masters: dict, tool: str, args: list, kind: str,
                                    tmp_path: Path) -> None:
    port = bad_masters[kind]
    done = run(tool, *args, env=ros_env(port, tmp_path))
    assert_one_line_error(done, 1, f"ERROR: http://localhost:{port} sent a reply that is "
                                   f"not XML-RPC {BAD_REPLIES[kind][1]}")


def test_parameter_files_that_cannot_be_loaded(graph: dict, tmp_path: Path) -> None:
    deep = tmp_path / "deep.yaml"
    deep.write_text("a: " + "[" * 10_000 + "]" * 10_000 + "\n")
    done = run("rosparam", "load", str(deep), env=graph)
    assert_one_line_error(done, 1, "ERROR: invalid YAML: collections nested too deeply")
    done = run("rosparam", "set", "/deep", "[" * 5_000 + "]" * 5_000, env=graph)
    assert_one_line_error(done, 1, "ERROR: invalid YAML: collections nested too deeply")
    latin = tmp_path / "latin.yaml"
    latin.write_bytes(b"name: x\ncity: Z\xfcrich\n")
    done = run("rosparam", "load", str(latin), env=graph)
    assert_one_line_error(done, 1, f"ERROR: file [{latin}] is not UTF-8 text: byte 0xfc on line 2")
    done = subprocess.run([str(BIN / "rosparam"), "load", "-"], env=graph, input=b"a: \xff\n",
                          capture_output=True, timeout=20)
    assert done.returncode == 1 and done.stderr.decode().splitlines() == [
        "ERROR: stdin is not UTF-8 text: byte 0xff on line 1 (save it as UTF-8)"]


# a small file whose value is 70 MB once its aliases are expanded
HUGE_YAML = ("s: &s " + "x" * 10_000 + "\nm: &m [" + ", ".join(["*s"] * 100) + "]\n"
             "big: [" + ", ".join(["*m"] * 70) + "]\n")


def test_a_value_over_the_masters_limit_names_the_limit(graph: dict, tmp_path: Path) -> None:
    huge = tmp_path / "huge.yaml"
    huge.write_text(HUGE_YAML)
    done = run("rosparam", "load", str(huge), "/huge", env=graph, timeout=60)
    assert_one_line_error(done, 1, "refused a request of 70", "its limit of 67108864 bytes (64 MiB)")
    code = ("import rospy\nrospy.init_node('big', anonymous=True)\n"
            "try:\n    rospy.set_param('/big', 'x' * 70_000_000)\n"
            "except Exception as exc:\n    print(type(exc).__name__, exc)\n")
    done = subprocess.run([PYTHON, "-c", code], env=graph, capture_output=True, text=True,
                          timeout=60)
    # rospy.set_param goes through the typed master client: its I/O error (an OSError)
    assert done.stdout.startswith("MasterIOError http://localhost:"), done.stdout + done.stderr
    assert "its limit of 67108864 bytes (64 MiB) per XML-RPC call" in done.stdout
    assert "not set" in run("rosparam", "get", "/big", env=graph).stderr
