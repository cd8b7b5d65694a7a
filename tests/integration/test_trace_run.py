"""``minros trace`` on real processes: a core, a listener and a talker, each started under
``minros trace`` with its own file; ``minros trace show`` merges the three into the course's
sequence with the values of that run, ``--follow`` shows it live, and the pcap of the run is
opened by Debian's tshark (XML-RPC as HTTP/XML, TCPROS connection headers decoded)."""

from __future__ import annotations

import json
import os
import re
import shlex
import shutil
import statistics
import subprocess
from pathlib import Path

import pytest

from support import EXAMPLES, IN_CI, PYTHON, Proc, free_port, ros_env, wait_for_master, wait_until

STRING_MD5 = "992ce8a1687cec8c8bd883ec73ca41d1"


def _events(path: Path):
    return [json.loads(line) for line in path.read_text().splitlines()]


def _traced(out: Path, argv, *, messages: bool = True):
    return [PYTHON, "-m", "minros", "trace", "-o", str(out), *(["--messages"] if messages else []),
            "--", *argv]


def _minros(args, env) -> str:
    done = subprocess.run([PYTHON, "-m", "minros", *args], env=env, capture_output=True,
                          text=True, timeout=60)
    assert done.returncode == 0, done.stdout + done.stderr
    return done.stdout


def _index(lines, *needles, start: int = 0) -> int:
    """The first line at or after ``start`` holding every needle."""
    for i in range(start, len(lines)):
        if all(needle in lines[i] for needle in needles):
            return i
    raise AssertionError(f"no line with {needles} after line {start}:\n" + "\n".join(lines))


@pytest.fixture(scope="module")
def traced_run(tmp_path_factory):
    """Core, listener (first) and talker, each traced to its own file; yields the files (one
    run for the whole module: the tests read it in different ways)."""
    tmp_path = tmp_path_factory.mktemp("traced_run")
    ros_home = tmp_path / "ros_home"
    (ros_home / "log").mkdir(parents=True)
    port = free_port()
    # two minros nodes of one host, and no MINROS_SHM=0: traced, they keep to TCPROS, the wire
    # courses teach (MINROSSHM's trace, asked with --shm: test_shm_run.py)
    env = ros_env(port, ros_home)
    env.pop("MINROS_SHM", None)
    files = {name: tmp_path / f"{name}.jsonl" for name in ("core", "listener", "talker")}
    core = Proc(_traced(files["core"], [PYTHON, "-m", "minros", "core", "-p", str(port)],
                        messages=False), env)
    follow = listener = talker = None
    try:
        wait_for_master(port)
        follow = Proc([PYTHON, "-m", "minros", "trace", "show", "--follow", "--topic", "/chatter",
                       str(files["listener"])], env)
        listener = Proc(_traced(files["listener"], [
            PYTHON, str(EXAMPLES / "talker_listener/listener.py"), "--count", "30"]), env)
        # the listener registers first, so the master announces the talker with publisherUpdate
        wait_until(lambda: files["listener"].exists() and "registerSubscriber" in
                   files["listener"].read_text(), 20, what="the listener's registration")
        talker = Proc(_traced(files["talker"], [
            PYTHON, str(EXAMPLES / "talker_listener/talker.py"), "--count", "40", "_rate:=20"]),
            env)
        listener.read_until("I heard", 20)
        live = follow.read_until("message 1:", 20)
        assert talker.popen.wait(30) == 0
        assert listener.popen.wait(10) == 0
        yield files, env, port, live
    finally:
        for proc in (talker, listener, follow, core):
            if proc is not None:
                proc.stop()


@pytest.mark.smoke
def test_show_prints_the_sequence_with_the_values_of_the_run(traced_run):
    files, env, port, live = traced_run
    talker_events, listener_events = _events(files["talker"]), _events(files["listener"])
    talker_uri = next(e["uri"] for e in talker_events if e["ev"] == "node")
    listener_uri = next(e["uri"] for e in listener_events if e["ev"] == "node")
    tcpros_port = next(int(e["local"].rsplit(":", 1)[1]) for e in talker_events
                       if e["ev"] == "tcp.open" and e["side"] == "accept")
    first = next(e["msg"]["data"] for e in listener_events
                 if e["ev"] == "tcpros.frame" and e.get("topic") == "/chatter")
    out = _minros(["trace", "show", "--topic", "/chatter", str(files["core"]),
                   str(files["listener"]), str(files["talker"])], env)
    lines = out.splitlines()
    assert f"master http://localhost:{port}/, 4 processes" in out  # core, rosout, both nodes
    i = _index(lines, "[1]", "/listener -> /master",
               f'registerSubscriber("/listener", "/chatter", "std_msgs/String", "{listener_uri}")')
    i = _index(lines, "[0]", "/talker -> /master",
               f'registerPublisher("/talker", "/chatter", "std_msgs/String", "{talker_uri}")',
               start=i + 1)
    assert f'["{listener_uri}"]' in lines[i + 1]  # the master's answer names the subscriber
    i = _index(lines, "[2]", "/master -> /listener",
               f'publisherUpdate("/master", "/chatter", ["{talker_uri}"])', start=i + 1)
    i = _index(lines, "[3]", "/listener -> /talker",
               'requestTopic("/listener", "/chatter", [["TCPROS"]])', start=i + 1)
    i = _index(lines, "[4]", f'<- 1, "ready on localhost:{tcpros_port}", '
                             f'["TCPROS", "localhost", {tcpros_port}]', start=i + 1)
    i = _index(lines, "[5]", "/listener -> /talker", f":{tcpros_port}", start=i + 1)
    i = _index(lines, "[5]", "/listener -> /talker", "connection header", start=i + 1)
    header = lines[i + 1:i + 7]
    assert [line.strip() for line in header] == [
        "callerid=/listener", f"md5sum={STRING_MD5}", "message_definition=string data",
        "tcp_nodelay=0", "topic=/chatter", "type=std_msgs/String"]
    i = _index(lines, "[5]", "/talker -> /listener", "connection header", start=i + 1)
    assert lines[i + 2].strip() == "latching=0"
    i = _index(lines, "[6]", "/talker -> /listener", "message 1: length prefix", start=i + 1)
    body = first.encode()
    assert lines[i + 1].strip().startswith("body " + len(body).to_bytes(4, "little").hex())
    assert lines[i + 2].strip() == "= " + json.dumps({"data": first})
    # every step line is in the course's order for a listener that registered first
    steps = re.findall(r"^\s*\[(\d)\]\s+\+", out, re.M)
    assert steps[:9] == ["1", "0", "2", "3", "4", "5", "5", "5", "6"], out
    # --follow printed the same sequence live, from the listener's own trace
    assert re.search(r"^topic /chatter: \[1\].*registerSubscriber", live, re.M), live
    assert re.search(r"^topic /chatter: \[2\].*publisherUpdate", live, re.M), live


def test_a_traced_talker_keeps_its_rate(traced_run):
    files, _env, _port, _live = traced_run
    sent = [e["t"] for e in _events(files["talker"])
            if e["ev"] == "tcpros.frame" and e.get("topic") == "/chatter" and e["dir"] == "out"]
    assert len(sent) >= 20
    gaps = [b - a for a, b in zip(sent, sent[1:])]
    assert abs(statistics.median(gaps) - 0.05) < 0.005, gaps  # _rate:=20


def test_tshark_decodes_the_pcap_of_the_run(traced_run, tmp_path):
    if shutil.which("tshark") is None:
        if IN_CI:
            pytest.fail("tshark is missing: scripts/install-ros-reference.sh installs it")
        pytest.skip("tshark is not installed (apt install tshark)")
    files, env, _port, _live = traced_run
    capture = tmp_path / "run.pcap"
    out = _minros(["trace", "pcap", *map(str, files.values()), "-o", str(capture)], env)
    command = next(line.strip() for line in out.splitlines() if line.strip().startswith("tshark"))
    argv = shlex.split(command) + ["-T", "fields", "-E", "separator=|", "-e", "tcp.srcport",
                                   "-e", "xml.cdata", "-e", "tcpros.header_field"]
    done = subprocess.run(argv, capture_output=True, text=True, timeout=60,
                          env=dict(os.environ, HOME=str(tmp_path)))
    assert done.returncode == 0, done.stderr
    rows = [line.split("|") for line in done.stdout.splitlines()]
    xml = [row[1] for row in rows if row[1]]
    headers = [row[2] for row in rows if row[2]]
    # the XML-RPC calls, decoded from HTTP by tshark's own dissectors
    assert any(v.startswith("registerPublisher,/talker,/chatter,std_msgs/String") for v in xml)
    assert any(v.startswith("registerSubscriber,/listener,/chatter") for v in xml)
    assert any(v.startswith("publisherUpdate,/master,/chatter") for v in xml)
    assert any(v.startswith("requestTopic,/listener,/chatter,TCPROS") for v in xml)
    # both connection headers of /chatter, field by field
    sub = next(h for h in headers if "callerid=/listener" in h and "topic=/chatter" in h)
    pub = next(h for h in headers if "callerid=/talker" in h and "topic=/chatter" in h)
    assert f"md5sum={STRING_MD5}" in sub and "tcp_nodelay=0" in sub
    assert "latching=0" in pub and "type=std_msgs/String" in pub


def test_traced_minros_nodes_keep_to_tcpros_unless_asked(tmp_path):
    """Issue 38 item 12: between two minros nodes a trace showed only XML-RPC (they took shared
    memory). Traced, a node speaks TCPROS only (the run above: the listener offers
    [["TCPROS"]] with MINROS_SHM unset); with ``minros trace --shm`` shared memory again."""
    ros_home = tmp_path / "ros_home"
    (ros_home / "log").mkdir(parents=True)
    port = free_port()
    env = ros_env(port, ros_home)
    env.pop("MINROS_SHM", None)
    probe = ("import minros.node as n; print([h.protocol for h in n.Node(argv=['p']).protocols])")
    plain = subprocess.run([PYTHON, "-c", probe], env=env, capture_output=True, text=True,
                           timeout=60)
    runs = {}
    for flags in ([], ["--shm"]):
        done = subprocess.run([PYTHON, "-m", "minros", "trace", "-o", str(tmp_path / "p.jsonl"),
                               *flags, "--", PYTHON, "-c", probe],
                              env=env, capture_output=True, text=True, timeout=60)
        assert done.returncode == 0, done.stderr
        runs[tuple(flags)] = done.stdout.strip()
    if "MINROSSHM" not in plain.stdout:
        pytest.skip("no shared memory on this system")
    assert runs[()] == "['TCPROS']"
    assert runs[("--shm",)] == "['MINROSSHM', 'TCPROS']"
