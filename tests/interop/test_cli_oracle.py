"""minros's rostopic/rosnode/rosparam/rosservice against Debian's, on one graph.

One Debian rosmaster, one rospy demo node (Debian's rospy) and one minros demo node are
shared by the module; every case runs the minros tool and the Debian tool with the same
arguments and requires the same exit status and the same stdout, masking only ports, pids,
anonymous-name suffixes, times and sequence numbers (tests/compare.py).
"""

from __future__ import annotations

import subprocess
import time
from pathlib import Path

import pytest

from compare import Outcome, assert_same  # noqa: E402
from support import (  # noqa: E402
    PYTHON,
    REFERENCE_PYTHON,
    Proc,
    free_port,
    reference_env,
    require_reference,
    ros_env,
    wait_for_master,
    wait_until,
)

pytestmark = pytest.mark.interop

DEMO = str(Path(__file__).resolve().parent.parent / "integration" / "cli_demo_node.py")
BIN = Path(PYTHON).parent
PARAMS = """\
demo:
  int: 7
  float: 2.5
  str: hello world
  multi: "line one\\nline two"
  bool: true
  list: [1, two, 3.0]
  nested: {a: 1, b: {c: x}}
gain: -3
"""


class Graph:
    def __init__(self, port: int, env: dict, renv: dict) -> None:
        self.port = port
        self.env = env
        self.renv = renv

    def _start(self, argv: list, env: dict, stdin: str | None) -> subprocess.Popen:
        return subprocess.Popen(argv, env=env, stdin=subprocess.PIPE, stdout=subprocess.PIPE,
                                stderr=subprocess.PIPE, text=True, start_new_session=True)

    @staticmethod
    def _finish(proc: subprocess.Popen, argv: list, stdin: str | None, timeout: float) -> Outcome:
        try:
            out, err = proc.communicate(stdin, timeout=timeout)
        except subprocess.TimeoutExpired:
            proc.kill()
            out, err = proc.communicate()
            raise AssertionError(f"{argv} did not finish within {timeout}s: {out}{err}") from None
        return Outcome(argv, proc.returncode, out, err)

    def ours(self, tool: str, *args: str, stdin: str | None = None, timeout: float = 20) -> Outcome:
        argv = [str(BIN / tool), *args]
        return self._finish(self._start(argv, self.env, stdin), [tool, *args], stdin, timeout)

    def reference(self, tool: str, *args: str, stdin: str | None = None, timeout: float = 20) -> Outcome:
        argv = [f"/usr/bin/{tool}", *args]
        return self._finish(self._start(argv, self.renv, stdin), argv, stdin, timeout)

    def both(self, tool: str, *args: str, stdin: str | None = None, timeout: float = 20) -> tuple:
        """Run both tools at once (the graph is the same; halves the wall time)."""
        mine = self._start([str(BIN / tool), *args], self.env, stdin)
        ref_argv = [f"/usr/bin/{tool}", *args]
        theirs = self._start(ref_argv, self.renv, stdin)
        return (self._finish(mine, [tool, *args], stdin, timeout),
                self._finish(theirs, ref_argv, stdin, timeout))

    def run_cases(self, cases: list) -> dict:
        """Read-only cases a few at a time; service calls one after the other, because
        Debian's rosservice call registers a node (with services) that a concurrent
        ``list`` would see."""
        calls = [c for c in cases if c[:2] == ("rosservice", "call")]
        others = [c for c in cases if c not in calls]
        results = dict(zip(others, self.many(others)))
        results.update((case, self.both(*case, timeout=60)) for case in calls)
        return results

    def many(self, cases: list, workers: int = 4) -> list:
        """``both`` for each case, a few at a time; results in the order of ``cases``."""
        from concurrent.futures import ThreadPoolExecutor

        with ThreadPoolExecutor(max_workers=workers) as pool:
            return list(pool.map(lambda case: self.both(*case, timeout=60), cases))


@pytest.fixture(scope="module")
def graph(tmp_path_factory):
    require_reference()
    home = tmp_path_factory.mktemp("cli_oracle") / "ros_home"
    (home / "log").mkdir(parents=True)
    port = free_port()
    env = ros_env(port, home)
    renv = reference_env(env)
    procs = [Proc(["/usr/bin/rosmaster", "--core", "-p", str(port)], renv)]
    try:
        wait_for_master(port)
        rospy_node = Proc([REFERENCE_PYTHON, DEMO, "rospy_demo", "--listen", "/minros_demo_chatter"], renv)
        procs.append(rospy_node)
        minros_node = Proc([PYTHON, DEMO, "minros_demo", "--listen", "/rospy_demo_chatter"], env)
        procs.append(minros_node)
        rospy_node.read_until("ready", 30)
        minros_node.read_until("ready", 30)
        g = Graph(port, env, renv)
        params = home / "params.yaml"
        params.write_text(PARAMS)
        loaded = g.reference("rosparam", "load", str(params))
        assert loaded.status == 0, loaded.stderr
        # both listeners connected to the other's chatter
        wait_until(lambda: "inbound" in g.ours("rosnode", "info", "/minros_demo").stdout
                   and "inbound" in g.ours("rosnode", "info", "/rospy_demo").stdout,
                   15, interval=0.2, what="chatter connections")
        yield g
    finally:
        for proc in reversed(procs):
            proc.stop()


XMLRPC_CASES = [
    # rosparam
    ("rosparam", "list"),
    ("rosparam", "list", "/demo"),
    ("rosparam", "get", "/demo"),
    ("rosparam", "get", "-p", "/demo"),
    ("rosparam", "get", "/demo/multi"),
    ("rosparam", "get", "/demo/list"),
    ("rosparam", "get", "/gain"),
    ("rosparam", "dump"),
    ("rosparam", "get", "/missing"),
    # rosnode
    ("rosnode", "list"),
    ("rosnode", "list", "-a"),
    ("rosnode", "info", "/rospy_demo"),
    ("rosnode", "info", "/minros_demo"),
    ("rosnode", "info", "-q", "/minros_demo"),
    ("rosnode", "info", "/missing"),
    ("rosnode", "ping", "-c", "1", "/minros_demo"),
    ("rosnode", "ping", "-c", "1", "/rospy_demo"),
    ("rosnode", "ping", "/missing"),
    ("rosnode", "machine"),
    ("rosnode", "kill", "/missing"),
    # rosservice
    ("rosservice", "list"),
    ("rosservice", "list", "-n"),
    ("rosservice", "type", "/minros_demo/set_bool"),
    ("rosservice", "uri", "/rospy_demo/set_bool"),
    ("rosservice", "node", "/minros_demo/trigger"),
    ("rosservice", "args", "/minros_demo/set_bool"),
    ("rosservice", "args", "/rospy_demo/get_loggers"),
    ("rosservice", "info", "/minros_demo/set_bool"),
    ("rosservice", "info", "/rospy_demo/set_logger_level"),
    ("rosservice", "find", "std_srvs/Trigger"),
    ("rosservice", "type", "/missing"),
    ("rosservice", "uri", "/missing"),
    ("rosservice", "info", "/missing"),
    ("rosservice", "call", "/missing"),
    ("rosservice", "call", "/minros_demo/set_bool", "true"),
    ("rosservice", "call", "/rospy_demo/set_bool", "{data: true}"),
    ("rosservice", "call", "-v", "/rospy_demo/set_bool", "false"),
    ("rosservice", "call", "/rospy_demo/get_loggers"),
    # rostopic (master queries)
    ("rostopic", "list"),
    ("rostopic", "list", "-v"),
    ("rostopic", "list", "-s"),
    ("rostopic", "list", "--host"),
    ("rostopic", "list", "/rosout"),
    ("rostopic", "info", "/pose"),
    ("rostopic", "info", "/rospy_demo_chatter"),
    ("rostopic", "info", "/cmd"),
    ("rostopic", "info", "/missing"),
    ("rostopic", "type", "/pose"),
    ("rostopic", "type", "/pose/pose/position"),
    ("rostopic", "type", "/missing"),
    ("rostopic", "find", "std_msgs/String"),
    ("rostopic", "find", "geometry_msgs/PoseStamped"),
]


@pytest.fixture(scope="module")
def oracle_runs(graph: Graph) -> dict:
    """Every read-only case run once, a few at a time (the cases do not change the graph)."""
    return graph.run_cases(XMLRPC_CASES)


@pytest.mark.parametrize("case", XMLRPC_CASES, ids=[" ".join(c) for c in XMLRPC_CASES])
def test_same_as_debian(oracle_runs: dict, case: tuple) -> None:
    ours, reference = oracle_runs[case]
    assert_same(ours, reference)


def test_param_set_merges_and_types_like_rosparam(graph: Graph) -> None:
    """`set` with YAML values (typed, a dict merges) leaves the same tree as Debian's rosparam."""
    values = [("i", "42"), ("f", "-0.5"), ("s", "'007'"), ("b", "false"), ("l", "[1, [2, 3], a]"),
              ("d", "{x: 1, y: {z: 2}}"), ("d", "{w: 0}"), ("neg", "-1")]
    from concurrent.futures import ThreadPoolExecutor

    def set_all(prefix: str, run) -> None:
        for key, value in values:
            result = run("rosparam", "set", f"{prefix}/{key}", value)
            assert result.status == 0, result.stderr

    with ThreadPoolExecutor(2) as pool:  # the two sequences touch different namespaces
        for future in [pool.submit(set_all, "/ours", graph.ours), pool.submit(set_all, "/ref", graph.reference)]:
            future.result()
    ours, reference = graph.ours("rosparam", "get", "/ours"), graph.reference("rosparam", "get", "/ref")
    assert_same(ours, reference)
    assert "w: 0" in ours.stdout and "x: 1" in ours.stdout  # merged, not replaced


def test_param_load_delete_like_rosparam(graph: Graph, tmp_path: Path) -> None:
    doc = tmp_path / "p.yaml"
    doc.write_text("a: 1\nb: {c: [1, 2]}\n---\n_ns: sub\nd: deg(180)\n")
    assert graph.ours("rosparam", "load", str(doc), "/lo").status == 0
    assert graph.reference("rosparam", "load", str(doc), "/lr").status == 0
    assert_same(graph.ours("rosparam", "get", "/lo"), graph.reference("rosparam", "get", "/lr"))
    assert graph.ours("rosparam", "load", "-", "/so", stdin="e: [x]\n").status == 0
    assert graph.ours("rosparam", "get", "/so/e").stdout == "- x\n\n"  # yaml.dump + newline, as rosparam
    assert graph.ours("rosparam", "delete", "/lo/b").status == 0
    assert graph.reference("rosparam", "delete", "/lr/b").status == 0
    assert_same(graph.ours("rosparam", "list", "/lo"), graph.reference("rosparam", "list", "/lr"),
                extra=[("^/l[or]/", "/L/")])
    # dump of a namespace to a file, then both files are the same YAML
    assert graph.ours("rosparam", "dump", str(tmp_path / "o.yaml"), "/demo").status == 0
    assert graph.reference("rosparam", "dump", str(tmp_path / "r.yaml"), "/demo").status == 0
    assert (tmp_path / "o.yaml").read_text() == (tmp_path / "r.yaml").read_text()


def test_echo_field_and_noarr_like_rostopic(graph: Graph) -> None:
    cases = [("rostopic", "echo", "-n", "1", "/pose/pose/position"),
             ("rostopic", "echo", "-n", "1", "--noarr", "/pose"),
             ("rostopic", "echo", "-n", "1", "--nostr", "/pose/header"),
             ("rostopic", "echo", "-n", "1", "-w", "4", "/pose/pose")]
    for ours, reference in graph.many(cases):
        assert_same(ours, reference)


def test_echo_latched_from_pub_like_rostopic(graph: Graph) -> None:
    """Our `pub` latches; both echos print the same message, in YAML and CSV."""
    pub = Proc([str(BIN / "rostopic"), "pub", "/latched_o", "geometry_msgs/Point", "1", "-2.5", "3000.0"], graph.env)
    try:
        pub.read_until("publishing and latching message", 15)
        cases = [("rostopic", "echo", "-n", "1", "/latched_o"), ("rostopic", "echo", "-n", "1", "-p", "/latched_o"),
                 ("rostopic", "echo", "-n", "1", "/latched_o/y")]
        for ours, reference in graph.many(cases):
            assert_same(ours, reference)
        assert graph.ours("rostopic", "echo", "-n", "1", "/latched_o").stdout == "x: 1.0\ny: -2.5\nz: 3000.0\n---\n"
    finally:
        pub.stop()


def test_pub_once_received_by_debian_echo(graph: Graph) -> None:
    """`pub -1` with a YAML dict, `now` header and positional args reaches Debian's echo."""
    pub = Proc([str(BIN / "rostopic"), "pub", "-1", "/once", "std_msgs/Header",
                "{seq: 0, stamp: now, frame_id: base}"], graph.env)
    try:
        pub.read_until("publishing and latching message for 3.0 seconds", 15)
        out = graph.reference("rostopic", "echo", "-n", "1", "/once").stdout
        pub.popen.wait(10)  # exits by itself after 3 s
        assert pub.popen.returncode == 0
    finally:
        pub.stop()
    assert "frame_id: \"base\"" in out
    assert "secs: 0\n" not in out.split("nsecs")[0]  # stamp was filled with now


def test_service_call_stdin_and_yaml_forms(graph: Graph) -> None:
    ours = graph.ours("rosservice", "call", "/rospy_demo/set_bool", stdin="data: true\n---\ndata: false\n")
    reference = graph.reference("rosservice", "call", "/rospy_demo/set_bool", stdin="data: true\n---\ndata: false\n")
    assert ours.status == 0, ours.stderr
    assert "set to True" in ours.stdout and "set to False" in ours.stdout
    assert reference.status == 0


def test_hz_and_bw_report_like_rostopic(graph: Graph) -> None:
    import re

    for verb, pattern in (("hz", r"average rate: ([\d.]+)\n\tmin: [\d.]+s max: [\d.]+s std dev: [\d.]+s window: \d+"),
                          ("bw", r"average: [\d.]+K?B/s\n\tmean: [\d.]+K?B min: [\d.]+K?B max: [\d.]+K?B window: \d+"),
                          ("delay", r"average delay: -?[\d.]+\n\tmin: -?[\d.]+s max: -?[\d.]+s std dev: [\d.]+s window: \d+")):
        topic = "/rospy_demo_chatter" if verb != "delay" else "/pose"
        proc = Proc([str(BIN / "rostopic"), verb, topic], graph.env)
        try:
            text = proc.read_until("window:", 10)
        finally:
            proc.stop()
        assert f"subscribed to [{topic}]" in text
        match = re.search(pattern, text)
        assert match, text
        if verb == "hz":
            assert 4.0 < float(match.group(1)) < 16.0, text  # the demo publishes at 10 Hz


def test_debian_tools_see_minros_pub_types(graph: Graph) -> None:
    pub = Proc([str(BIN / "rostopic"), "pub", "-r", "20", "/rated", "std_msgs/Int32", "--", "-7"], graph.env)
    try:
        wait_until(lambda: "/rated" in graph.reference("rostopic", "list", "-p").stdout, 15,
                   interval=0.2, what="rated publisher")
        reference = graph.reference("rostopic", "echo", "-n", "2", "/rated")
        assert reference.stdout == "data: -7\n---\ndata: -7\n---\n"
        assert_same(graph.ours("rostopic", "info", "/rated"), graph.reference("rostopic", "info", "/rated"))
    finally:
        pub.stop()


def test_kill_like_rosnode(graph: Graph) -> None:
    victim = Proc([PYTHON, DEMO, "victim"], graph.env)
    try:
        victim.read_until("ready", 20)
        result = graph.ours("rosnode", "kill", "/victim")
        assert result.status == 0
        assert result.stdout == "killing /victim\nkilled\n"
        deadline = time.monotonic() + 10
        while victim.alive() and time.monotonic() < deadline:
            time.sleep(0.05)
        assert not victim.alive()
    finally:
        victim.stop()


RSPY_CUSTOM_PUB = '''
import rospy, genpy.dynamic
text = "Header header\\nstring name\\nfloat64[] values\\ndemo_types/Point2[] points\\n" + "=" * 80 + \\
    "\\nMSG: std_msgs/Header\\nuint32 seq\\ntime stamp\\nstring frame_id\\n" + "=" * 80 + \\
    "\\nMSG: demo_types/Point2\\nfloat32 x\\nfloat32 y\\n"
classes = genpy.dynamic.generate_dynamic("demo_types/Reading", text)
Reading, Point2 = classes["demo_types/Reading"], classes["demo_types/Point2"]
rospy.init_node("custom_pub")
pub = rospy.Publisher("/custom", Reading, queue_size=1, latch=True)
msg = Reading(name="rospy", values=[0.25], points=[Point2(x=1.0, y=-1.0)])
msg.header.frame_id = "f"
pub.publish(msg)
print("ready", flush=True)
rospy.spin()
'''


def test_echo_rospy_type_nobody_installed(graph: Graph) -> None:
    """A rospy publisher of a type that exists only in its process: Debian's rostopic cannot
    print it, minros decodes it from the publisher's message_definition."""
    pub = Proc([REFERENCE_PYTHON, "-c", RSPY_CUSTOM_PUB], graph.renv)
    try:
        pub.read_until("ready", 30)
        ours, reference = graph.both("rostopic", "echo", "-n", "1", "/custom")
        assert reference.status != 0 or reference.stdout == ""  # "Cannot load message class ..."
        assert ours.status == 0, ours.stderr
        assert ours.stdout.endswith('  frame_id: "f"\nname: "rospy"\nvalues: [0.25]\npoints: \n'
                                    "  - \n    x: 1.0\n    y: -1.0\n---\n"), ours.stdout
        ours = graph.ours("rostopic", "echo", "-n", "1", "-p", "/custom/points[0]")
        assert ours.stdout == "%time,field.x,field.y\n" + ours.stdout.splitlines()[1] + "\n"
        assert ours.stdout.splitlines()[1].endswith(",1.0,-1.0")
    finally:
        pub.stop()


def test_graph_of_mixed_nodes(graph: Graph) -> None:
    dot = graph.ours("rqt_graph" if (BIN / "rqt_graph").exists() else "minros",
                     *(() if (BIN / "rqt_graph").exists() else ("graph",))).stdout
    assert '"n__rospy_demo" -> "n__minros_demo" [label="/rospy_demo_chatter"];' in dot
    assert '"n__minros_demo" -> "n__rospy_demo" [label="/minros_demo_chatter"];' in dot
    assert "rosout" not in dot


def test_kill_both_ways(graph: Graph) -> None:
    """Our rosnode kills a rospy node; Debian's rosnode kills a minros node."""
    rospy_victim = Proc([REFERENCE_PYTHON, DEMO, "rospy_victim"], graph.renv)
    minros_victim = Proc([PYTHON, DEMO, "minros_victim"], graph.env)
    try:
        rospy_victim.read_until("ready", 30)
        minros_victim.read_until("ready", 30)
        ours = graph.ours("rosnode", "kill", "/rospy_victim")
        reference = graph.reference("rosnode", "kill", "/minros_victim")
        assert ours.stdout == "killing /rospy_victim\nkilled\n" and ours.status == 0
        assert reference.stdout == "killing /minros_victim\nkilled\n" and reference.status == 0
        wait_until(lambda: not rospy_victim.alive() and not minros_victim.alive(), 15, what="victims exit")
    finally:
        rospy_victim.stop()
        minros_victim.stop()


def test_ping_all_and_service_wait(graph: Graph) -> None:
    ours = graph.ours("rosnode", "ping", "--all")
    assert ours.status == 0
    for node in ("/minros_demo", "/rospy_demo"):
        assert f" * {node}\n" in ours.stdout and f"pinging {node} with a timeout of 3.0s" in ours.stdout
    assert ours.stdout.count("xmlrpc reply from http://localhost:") >= 2
    ours = graph.ours("rosservice", "call", "--wait", "/minros_demo/trigger")
    assert ours.stdout == 'success: True\nmessage: "triggered"\n'


MINROS_MASTER_CASES = [
    ("rostopic", "list", "-v"), ("rostopic", "info", "/pose"), ("rosnode", "list", "-a"),
    ("rosnode", "info", "/rospy_demo"), ("rosservice", "list", "-n"),
    ("rosservice", "info", "/minros_demo/set_bool"), ("rosparam", "get", "/"),
    ("rosservice", "call", "/rospy_demo/set_bool", "true"),
]


def test_same_as_debian_on_minros_master(tmp_path: Path) -> None:
    """The same comparison with minros's master in the middle."""
    home = tmp_path / "ros_home"
    (home / "log").mkdir(parents=True)
    port = free_port()
    env = ros_env(port, home)
    renv = reference_env(env)
    procs = [Proc([PYTHON, "-m", "minros.master", "-p", str(port)], env)]
    try:
        wait_for_master(port)
        procs.append(Proc([REFERENCE_PYTHON, DEMO, "rospy_demo", "--listen", "/minros_demo_chatter"], renv))
        procs.append(Proc([PYTHON, DEMO, "minros_demo"], env))
        for proc in procs[1:]:
            proc.read_until("ready", 30)
        g = Graph(port, env, renv)
        assert g.ours("rosparam", "set", "/k", "{a: [1, 2], b: x}").status == 0
        wait_until(lambda: "inbound" in g.ours("rosnode", "info", "/rospy_demo").stdout, 15,
                   interval=0.2, what="chatter connection")
        for ours, reference in g.run_cases(MINROS_MASTER_CASES).values():
            assert_same(ours, reference)
    finally:
        for proc in reversed(procs):
            proc.stop()
