"""``minros ros2`` between real ROS 1 (rospy_tutorials' nodes run by minros, Debian's rospy and
roscpp) and real ROS 2 (rclpy from PyPI: Jazzy on Fast DDS 2.14, Kilted on Fast DDS 3.2).

Per distro, one network namespace holds one master (minros core), one bridge (dynamic, as
ros1_bridge's dynamic_bridge), one rclpy agent (tests/ros2_agent.py) and one minros ROS 1 agent
(tests/ros1_bridge_agent.py); each test adds the few programs it needs. Nothing leaves the
namespace's loopback.
"""

from __future__ import annotations

import io
import subprocess
import sys
import time
from pathlib import Path

import pytest

from bridge_support import (
    CLIENT,
    LISTENER,
    NODE_CPP,
    SERVER,
    TALKER,
    World,
    drain,
    lines_of,
)
from ros2_support import HASHES, cdr_string, context, require_ros2, wait_for
from support import PYTHON, REFERENCE_PYTHON, build_roscpp, require_reference

pytestmark = [pytest.mark.interop, pytest.mark.timeout(300)]

STRING = "std_msgs/msg/String"
COUNT = 1000


@pytest.fixture(scope="module", params=["jazzy", "kilted"])
def world(request, tmp_path_factory):
    distro = request.param
    require_ros2(distro)
    tmp = tmp_path_factory.mktemp(f"bridge-{distro}")
    w = World(tmp)
    try:
        agent = w.rclpy(distro)
        started = time.monotonic()
        bridge = w.bridge(distro=distro)
        seen = agent("graph", want_node="ros_bridge", timeout=20)
        listed_after = time.monotonic() - started
        bridge.read_until("minros ros2: bridging the ROS master", 30)
        ros1 = w.ros1_agent()
        yield {"distro": distro, "w": w, "agent": agent, "bridge": bridge, "ros1": ros1,
               "tmp": tmp, "listed_after": listed_after, "nodes": seen["nodes"]}
    finally:
        w.close()


@pytest.fixture(scope="module")
def scripts(tmp_path_factory):
    folder = tmp_path_factory.mktemp("bridge-scripts")
    for name, text in (("talker.py", TALKER), ("listener.py", LISTENER), ("server.py", SERVER),
                       ("client.py", CLIENT)):
        (folder / name).write_text(text)
    return folder


def bridged(world, needle: str, timeout: float = 20) -> None:
    """Wait until the bridge says it bridges ``needle`` (``/topic ROS 1 -> ROS 2``)."""
    world["bridge"].read_until(f"bridging {needle}", timeout)


# -- the bridge in both graphs ---------------------------------------------------------------


def test_bridge_is_in_rclpys_node_list_within_a_second_of_starting(world):
    assert ["ros_bridge", "/"] in world["nodes"]
    # from the bridge process's start (python, imports, the DDS participant) to rclpy's list
    assert world["listed_after"] < 1.0, f"rclpy listed the bridge after {world['listed_after']:.2f} s"


# -- talkers and listeners, 1000 of 1000 in order -----------------------------------------------


def _rclpy_listener(world, sid: str, topic: str) -> None:
    world["agent"]("sub", id=sid, topic=topic, type=STRING, qos={"depth": COUNT + 100})


def _check_endpoint(world, topic: str, kind: str) -> None:
    """The bridge's endpoint of ``topic`` in rclpy's graph: its node and the type's hash."""
    info = wait_for(lambda: [e for e in world["agent"]("graph", topic=topic)[kind]
                             if e["node"] == "ros_bridge"], 10, f"the bridge's {kind} of {topic}")
    assert [(e["namespace"], e["type"], e["hash"]) for e in info] == [("/", STRING, HASHES[STRING])]


def test_rospy_tutorials_talker_to_rclpy_listener(world):
    """minros runs rospy_tutorials' talker (10 Hz, "hello world <time>"); on simulated time
    the ROS 1 agent publishes /clock in 0.1 s steps (at 1 kHz) and waits for each message, so
    the run takes a second, not 100 s. The rclpy listener gets every one, in order."""
    agent, ros1, w = world["agent"], world["ros1"], world["w"]
    topic = "/tutorial_chatter"
    _rclpy_listener(world, "tut", topic)
    ros1("sub", id="tut_ref", topic=topic, type="std_msgs/String")
    ros1("param", name="/use_sim_time", value=True)
    talker = w.start([PYTHON, "-m", "minros", "run", "rospy_tutorials", "talker",
                      f"chatter:={topic}"], "talker")
    try:
        talker.read_until("hello world", 30)  # its first message (time 0, before any /clock)
        ros1("param", name="/use_sim_time", delete=True)
        bridged(world, f"{topic} ROS 1 -> ROS 2")
        _check_endpoint(world, topic, "publishers")
        assert ros1("sub_connections", ids=["tut_ref"])["counts"] == {"tut_ref": 1}
        assert agent("counts", ids=["tut"])["counts"] == {"tut": 1}
        # warm up: until the bridge's subscriber is connected, messages reach only the agent
        t = 0.0
        for _ in range(200):
            t = ros1("clock", id="tut_ref", start=t, step=0.1, count=1)["time"]
            if agent("received", id="tut", count=1, timeout=0.05, items=False)["count"]:
                break
        t = ros1("clock", id="tut_ref", start=t, step=0.1, count=5)["time"]
        start = t
        answer = ros1("clock", id="tut_ref", start=t, step=0.1, count=COUNT, rate=1000)
        assert answer["missed"] == 0

        def run_of(texts):  # the messages of the run: those stamped after its start
            return [x for x in texts if float(x.rsplit(" ", 1)[1]) > start + 0.05]
        sent = run_of([bytes.fromhex(x)[4:].decode() for x in
                       ros1("received", id="tut_ref", count=10**6, timeout=0.2)["items"]])
        assert len(sent) == COUNT and len(set(sent)) == COUNT
        assert all(x.startswith("hello world ") for x in sent)
        deadline = time.monotonic() + 20
        while True:
            got = run_of(agent("received", id="tut", count=10**6, timeout=0.1)["items"])
            if len(got) >= COUNT or time.monotonic() > deadline:
                break
        assert got == sent, "the rclpy listener did not get the talker's 1000, in order"
    finally:
        talker.stop()


def _talk_ros1_to_rclpy(world, argv, reference: bool, topic: str) -> None:
    """Run a ROS 1 talker (``argv`` + topic, count, hz), warm it up until rclpy hears it, then
    1000 messages: rclpy must hear all, in order."""
    agent, w = world["agent"], world["w"]
    sid = "l" + topic.replace("/", "_")
    _rclpy_listener(world, sid, topic)
    talker = w.start([*argv, topic, str(COUNT), "1000"], "talker", reference=reference,
                     stdin=subprocess.PIPE)
    try:
        talker.read_until("talker up", 30)
        bridged(world, f"{topic} ROS 1 -> ROS 2")
        assert agent("received", id=sid, count=1, timeout=20, items=False)["count"] >= 1
        talker.popen.stdin.write(b"go\n")
        talker.popen.stdin.flush()
        talker.read_until(f"sent {COUNT}", 30)
        got = agent("received", id=sid, count=10**6, timeout=0.5)["items"]
        deadline = time.monotonic() + 20
        while sum(x.startswith("msg ") for x in got) < COUNT and time.monotonic() < deadline:
            got = agent("received", id=sid, count=10**6, timeout=0.2)["items"]
        assert [x for x in got if x.startswith("msg ")] == [f"msg {i}" for i in range(COUNT)]
    finally:
        talker.stop()


def _talk_rclpy_to_ros1(world, listener_argv, reference: bool, topic: str, heard: str) -> None:
    """An rclpy talker, warmed up until the ROS 1 listener hears it, then 1000 messages: the
    listener must hear all, in order (``heard``: the text before each in its output)."""
    agent, w = world["agent"], world["w"]
    pid = "t" + topic.replace("/", "_")
    listener = w.start(listener_argv, "listener", reference=reference)
    try:
        agent("pub", id=pid, topic=topic, type=STRING, qos={"depth": COUNT + 100})
        bridged(world, f"{topic} ROS 2 -> ROS 1")
        deadline = time.monotonic() + 30
        while True:
            agent("publish", id=pid, count=1, prefix="warm")
            try:
                listener.read_until(f"{heard}warm", 0.1)
                break
            except AssertionError:
                assert time.monotonic() < deadline, "the ROS 1 listener heard no warm-up message"
        agent("publish", id=pid, count=COUNT, prefix="msg", rate=1000)
        lines = lines_of(listener, f"{heard}msg ", COUNT, 30)
        assert [line.split(heard, 1)[1].strip() for line in lines] == \
            [f"msg {i}" for i in range(COUNT)]
    finally:
        listener.stop()
        agent("destroy", id=pid)


def test_rclpy_talker_to_rospy_tutorials_listener(world):
    topic = "/tutorial_listen"
    _talk_rclpy_to_ros1(world, [PYTHON, "-m", "minros", "run", "rospy_tutorials", "listener",
                                f"chatter:={topic}"], False, topic, "I heard ")


def test_debian_rospy_talker_to_rclpy_listener(world, scripts):
    require_reference()
    _talk_ros1_to_rclpy(world, [REFERENCE_PYTHON, str(scripts / "talker.py")], True,
                        "/rospy_chatter")


def test_rclpy_talker_to_debian_rospy_listener(world, scripts):
    require_reference()
    topic = "/rospy_listen"
    _talk_rclpy_to_ros1(world, [REFERENCE_PYTHON, str(scripts / "listener.py"), topic,
                                str(COUNT)], True, topic, "got ")


@pytest.fixture(scope="module")
def roscpp_node(tmp_path_factory) -> Path:
    return build_roscpp(NODE_CPP, "bridge_node", tmp_path_factory.mktemp("roscpp"),
                        ("roscpp", "std_msgs"))


def test_roscpp_talker_to_rclpy_listener(world, roscpp_node):
    _talk_ros1_to_rclpy(world, [str(roscpp_node), "talker"], True, "/roscpp_chatter")


def test_rclpy_talker_to_roscpp_listener(world, roscpp_node):
    topic = "/roscpp_listen"
    _talk_rclpy_to_ros1(world, [str(roscpp_node), "listener", topic, str(COUNT)], True, topic,
                        "got ")


# -- services each way ------------------------------------------------------------------------


def test_services_rclpy_client_to_rospy_server_and_rospy_client_to_rclpy_server(world, scripts):
    require_reference()
    agent, w = world["agent"], world["w"]
    server = w.start([REFERENCE_PYTHON, str(scripts / "server.py"), "/ros1_set",
                      "/ros1_trigger"], "server", reference=True)
    try:
        server.read_until("serving", 30)
        bridged(world, "service /ros1_set")
        bridged(world, "service /ros1_trigger")
        answer = agent("call", id="c_set", name="/ros1_set", type="std_srvs/srv/SetBool",
                       data=True, count=3)
        assert answer["ready"] and answer["results"] == \
            [{"success": True, "message": "rospy set True"}] * 3
        answer = agent("call", id="c_set", name="/ros1_set", type="std_srvs/srv/SetBool",
                       data=False)
        assert answer["results"] == [{"success": False, "message": "rospy set False"}]
        answer = agent("call", id="c_trig", name="/ros1_trigger", type="std_srvs/srv/Trigger")
        assert answer["results"] == [{"success": True, "message": "rospy triggered"}]
        # the bridge's server endpoints carry the request's and the response's hashes, as
        # rclpy's do (a minros participant in the namespace reads SEDP)
        ctx = context(w.ns)
        try:
            assert ctx.graph.wait_until(
                lambda g: g.endpoints_of("rr/ros1_setReply", "publisher")
                and g.endpoints_of("rq/ros1_setRequest", "subscription"), 10)
            assert [e.type_hash for e in ctx.graph.endpoints_of("rq/ros1_setRequest",
                                                                "subscription")] == \
                [HASHES["std_srvs/srv/SetBool_Request"]]
            assert [e.type_hash for e in ctx.graph.endpoints_of("rr/ros1_setReply",
                                                                "publisher")] == \
                [HASHES["std_srvs/srv/SetBool_Response"]]
        finally:
            ctx.shutdown()
    finally:
        server.stop()
    agent("serve", id="s_set", name="/rclpy_set", type="std_srvs/srv/SetBool")
    agent("serve", id="s_trig", name="/rclpy_trigger", type="std_srvs/srv/Trigger")
    client = w.start([REFERENCE_PYTHON, str(scripts / "client.py"), "/rclpy_set",
                      "/rclpy_trigger"], "client", reference=True)
    try:
        out = client.read_until("trigger ->", 40)
        assert "setbool True -> True rclpy set True" in out
        assert "setbool False -> False rclpy set False" in out
        assert "trigger -> True rclpy triggered" in out
    finally:
        client.stop()
    # the ROS 1 server is gone: its bridge goes, and rclpy's client no longer finds a server
    world["bridge"].read_until("stopped bridging service /ros1_set", 10)
    assert wait_for(lambda: not agent("call", id="c_set", name="/ros1_set",
                                      type="std_srvs/srv/SetBool", timeout=0.2)["ready"],
                    10, "the bridged server to leave ROS 2")


# -- latched <-> transient local -----------------------------------------------------------


def test_latched_ros1_topic_reaches_a_late_rclpy_subscriber_and_back(world):
    agent, ros1 = world["agent"], world["ros1"]
    ros1("pub", id="latched", topic="/latched_state", type="std_msgs/String",
         md5="992ce8a1687cec8c8bd883ec73ca41d1", definition="string data\n", latch=True)
    ros1("publish", id="latched", hex=[cdr_string("old")[4:].hex(),
                                       cdr_string("latched state")[4:].hex()])
    # a ROS 2 subscriber joins later: the bridge connects, the latched message comes, and
    # the bridge's transient-local writer keeps it for the subscriber
    agent("sub", id="late", topic="/latched_state", type=STRING,
          qos={"durability": "transient_local", "depth": 1})
    got = agent("received", id="late", count=1, timeout=20)
    assert got["items"] == ["latched state"]
    publishers = agent("graph", topic="/latched_state")["publishers"]
    assert [(p["node"], p["durability"], p["hash"]) for p in publishers] == \
        [("ros_bridge", "TRANSIENT_LOCAL", HASHES[STRING])]
    # a second late subscriber gets it too (the writer's history), then ROS 2 -> ROS 1
    agent("sub", id="later", topic="/latched_state", type=STRING,
          qos={"durability": "transient_local", "depth": 1})
    assert agent("received", id="later", count=1, timeout=10)["items"] == ["latched state"]
    agent("pub", id="tl", topic="/ros2_latched", type=STRING,
          qos={"durability": "transient_local", "depth": 1})
    agent("publish", id="tl", count=2, prefix="ros2 state")
    ros1("sub", id="late1", topic="/ros2_latched", type="std_msgs/String")
    got = ros1("received", id="late1", count=1, timeout=20)
    assert [bytes.fromhex(h)[4:].decode() for h in got["items"]] == ["ros2 state 1"], got
    assert got["latching"] == ["1"] and got["callers"] == ["/ros_bridge"], got


# -- every type both sides ship, there and back ----------------------------------------------

#: what ROS 2 lacks, by field path: each comes back as its zero, except a message's own
#: Header seq, which the bridge counts per publisher (1, 2, ... as rospy does)
DROPPED = {
    "header.seq": "counted",                       # Header has no seq in ROS 2
    "seq": "counted",                              # std_msgs/Header itself
    "image.header.seq": "zero",                    # nested headers: 0
    "poses[].header.seq": "zero",
    "markers[].header.seq": "zero",
    "controls[].markers[].header.seq": "zero",
    "markers[].controls[].markers[].header.seq": "zero",
    "header.frame_id": "zero",                     # rosgraph_msgs/Log -> rcl_interfaces/Log
    "topics": "zero",                              # rosgraph_msgs/Log's topics
}
SAMPLES = 3


def _both_sides_ship(distro: str) -> list:
    """(ROS 1 type, mapping) of every installed ROS 1 type whose ROS 2 counterpart (not one
    made by minros) the pip ROS 2's wheels ship."""
    from minros.msgs.registry import list_types
    from minros.ros2.types import Mapper, registry
    from ros2_support import ROS2_HOME

    share = ROS2_HOME / distro / "share"
    mapper = Mapper(distro)
    out = []
    packages = {n.split("/")[0] for n in registry(distro).type_names("msg")} | {"tf", "uuid_msgs"}
    for package in sorted(packages):
        try:
            names = list_types(package)
        except LookupError:
            continue
        for ros1_type in names:
            m = mapper.message(ros1_type)
            pkg, _, short = m.ros2_type.split("/")
            if not m.generated and (share / pkg / "msg" / f"{short}.msg").exists():
                out.append((ros1_type, m))
    return out


def _set_path(value, path, new):
    """Set field ``path`` (``a.b``, ``a[].b``) of a plain message value to ``new``."""
    head, _, rest = path.partition(".")
    if head.endswith("[]"):
        for item in value[head[:-2]]:
            _set_path(item, rest, new)
    elif not rest:
        value[head] = new(value[head])
    else:
        _set_path(value[head], rest, new)


def _zero(value):
    if isinstance(value, str):
        return ""
    if isinstance(value, list):
        return []
    return 0


def _c_strings(value):
    if isinstance(value, dict):
        return {k: _c_strings(v) for k, v in value.items()}
    if isinstance(value, list):
        return [_c_strings(v) for v in value]
    if isinstance(value, str):
        return value.split("\0", 1)[0]
    return value


def test_every_type_both_sides_ship_goes_ros1_to_ros2_to_ros1_and_comes_back_equal(world):
    """Each type on a topic of its own: the ROS 1 agent publishes hypothesis samples on
    /rt/<type>, the bridge carries them to ROS 2, the rclpy agent's echo deserializes each with
    rclpy (which must accept every one), serializes it again and publishes it on
    /rt_back/<type>, and the bridge carries that back to the ROS 1 agent. What comes back is
    what was sent, but for what ROS 2 lacks (DROPPED) and strings cut at a NUL (ROS 2's are C
    strings)."""
    from minros.msgs import get_message_class
    from minros.msgs.testing import strategy_for, to_plain
    from minros.ros2.types.testing import samples

    agent, ros1, distro = world["agent"], world["ros1"], world["distro"]
    kinds = _both_sides_ship(distro)
    assert len(kinds) > 100
    dropped = {p for _t, m in kinds for p in m.all_dropped()}
    assert dropped == set(DROPPED), "fields ROS 2 lacks changed: name them in DROPPED"
    commands = []
    for ros1_type, _m in kinds:
        cls = get_message_class(ros1_type)
        commands.append({"op": "pub", "id": "rt " + ros1_type, "topic": "/rt/" + ros1_type,
                         "type": ros1_type, "md5": cls._md5sum, "definition": cls._full_text})
        commands.append({"op": "sub", "id": "back " + ros1_type, "topic": "/rt_back/" + ros1_type,
                         "type": ros1_type})
    ros1("many", commands=commands)
    agent("echo", topics=[["/rt/" + t, "/rt_back/" + t, m.ros2_type] for t, m in kinds])
    # every path made: the bridge's subscriber of each /rt topic, rclpy's echo subscription
    # matched with the bridge's writer, the bridge's subscription with the echo's writer, the
    # bridge's ROS 1 publisher of each /rt_back topic connected to the agent
    ids = ["rt " + t for t, _m in kinds]
    assert all(ros1("pub_connections", ids=ids, timeout=90)["counts"].values())
    counts = agent("counts", ids=["echo /rt/" + t for t, _m in kinds] +
                   ["echo out /rt/" + t for t, _m in kinds], timeout=60)["counts"]
    assert all(counts.values()), [k for k, v in counts.items() if not v]
    back = ["back " + t for t, _m in kinds]
    assert all(ros1("sub_connections", ids=back, timeout=60)["counts"].values())
    sent = {}
    publish = []
    for ros1_type, _m in kinds:
        msgs = samples(strategy_for(ros1_type), SAMPLES)
        sent[ros1_type] = msgs
        data = []
        for msg in msgs:
            buf = io.BytesIO()
            msg.serialize(buf)
            data.append(buf.getvalue().hex())
        publish.append({"op": "publish", "id": "rt " + ros1_type, "hex": data})
    ros1("many", commands=publish)
    deadline = time.monotonic() + 60
    for ros1_type, m in kinds:
        wanted = len(sent[ros1_type])  # (hypothesis gives fewer when there are fewer values)
        got = ros1("received", id="back " + ros1_type, count=wanted,
                   timeout=max(0.1, deadline - time.monotonic()))
        assert got["count"] == wanted, f"{ros1_type}: {got['count']} of {wanted} came back"
        assert got["callers"] == ["/ros_bridge"]
        cls = get_message_class(ros1_type)
        for k, (msg, data) in enumerate(zip(sent[ros1_type], got["items"]), start=1):
            want = _c_strings(to_plain(msg))
            for path in m.all_dropped():
                _set_path(want, path, (lambda _v, k=k: k) if DROPPED[path] == "counted"
                          else _zero)
            came = to_plain(cls().deserialize(bytes.fromhex(data)))
            assert came == want, f"{ros1_type}, sample {k}"
    echoed = agent("echo_report")
    assert echoed["failures"] == [], "rclpy's deserialize_message refused what the bridge sent"
    assert echoed["echoed"] == {"/rt/" + t: len(sent[t]) for t, _m in kinds}


# -- a type no wheel ships, through Cyclone DDS ----------------------------------------------

CUSTOM = (Path(__file__).resolve().parent.parent / "unit" / "ros2_fixtures"
          / "my_robot_msgs_Status.txt").read_text()
CUSTOM_TYPE = "my_robot_msgs/Status"


def _cyclone_types(mapper, ros2_type: str, out: list) -> list:
    """The IDL structs (dependencies first) of ``ros2_type`` as bridge_cyclone_agent builds
    them, from the ROS 2 type minros made."""
    from minros.ros2.types import dds_type_name

    struct = mapper.ros2.message(ros2_type)
    fields = []
    for f in struct.fields:
        ft = f.type
        base = ft.base
        if ft.is_nested:
            _cyclone_types(mapper, base, out)
            base = dds_type_name(base)
        fields.append([f.name, {"base": base, "kind": ft.kind or "scalar", "size": ft.size}])
    name = dds_type_name(ros2_type)
    if all(s["name"] != name for s in out):
        out.append({"name": name, "fields": fields})
    return out


def test_a_type_no_wheel_ships_goes_through_with_cyclone_dds_on_the_far_side(world):
    """A robot's own ROS 1 message (a definition nobody installed: the bridge has it only from
    its publisher's connection header) becomes a ROS 2 type made by minros; cyclonedds-python,
    which builds IDL types at run time, reads it on the far side and writes it back."""
    from bridge_support import BRIDGE_CYCLONE_AGENT, JsonAgent
    from minros.msgs.registry import REGISTRY, MsgContext
    from minros.msgs.spec import parse_msg, split_full_text
    from minros.msgs.testing import strategy_for, to_plain
    from minros.ros2.types import Mapper
    from minros.ros2.types.testing import ros2_plain_of_ros1, samples
    from ros2_support import CYCLONE_URI, cyclone_python, require_cyclone

    require_cyclone()
    ros1, w = world["ros1"], world["w"]
    context = MsgContext(search=False, fallback=REGISTRY)
    for block, text in split_full_text(CUSTOM):
        name = CUSTOM_TYPE if block is None else block
        context.add_spec(parse_msg(text, name, "fixture"))
    cls = context.get_class(CUSTOM_TYPE)
    mapper = Mapper(world["distro"])
    mapper.add_ros1_definition(CUSTOM_TYPE, CUSTOM)
    mapping = mapper.message(CUSTOM_TYPE)
    assert (mapping.ros2_type, mapping.generated) == ("my_robot_msgs/msg/Status", True)
    cyclone = JsonAgent(w.ns, cyclone_python(), BRIDGE_CYCLONE_AGENT, "cyclone_echo", w.tmp,
                        {"CYCLONEDDS_URI": CYCLONE_URI})
    w.agents.append(cyclone)
    made = cyclone("types", types=_cyclone_types(mapper, mapping.ros2_type, []))
    assert "my_robot_msgs::msg::dds_::Status_" in made["made"]
    cyclone("echo", type="my_robot_msgs::msg::dds_::Status_", topic="custom", out="custom_back")
    ros1("sub", id="custom_back", topic="/custom_back", type=CUSTOM_TYPE)
    ros1("pub", id="custom", topic="/custom", type=CUSTOM_TYPE, md5=cls._md5sum,
         definition=cls._full_text)
    bridged(world, "/custom ROS 1 -> ROS 2")

    def serialized(msg) -> str:
        buf = io.BytesIO()
        msg.serialize(buf)
        return buf.getvalue().hex()
    msgs = samples(strategy_for(CUSTOM_TYPE, context), 5)
    # the first message teaches the bridge the type; it goes on once Cyclone has one
    deadline = time.monotonic() + 20
    while not cyclone("received", count=1, timeout=0.2)["count"]:
        assert time.monotonic() < deadline, "Cyclone got nothing"
        ros1("publish", id="custom", hex=[serialized(msgs[0])], wait_for=1)
    warm = cyclone("received", count=1, timeout=0.5)["count"]
    bridged(world, "/custom_back ROS 2 -> ROS 1")
    assert ros1("sub_connections", ids=["custom_back"], timeout=20)["counts"]["custom_back"] == 1
    before = ros1("received", id="custom_back", count=0)["count"]
    ros1("publish", id="custom", hex=[serialized(m) for m in msgs])
    got = cyclone("received", count=warm + len(msgs), timeout=20)["items"][warm:]

    def c_plain(value):
        return _c_strings(value)
    assert got == [c_plain(ros2_plain_of_ros1(mapping, m)) for m in msgs]
    back = ros1("received", id="custom_back", count=before + len(msgs), timeout=20)
    items = back["items"][-len(msgs):]
    assert len(items) == len(msgs)
    seq0 = context.get_class(CUSTOM_TYPE)().deserialize(bytes.fromhex(items[0])).header.seq
    for k, (msg, data) in enumerate(zip(msgs, items)):
        want = _c_strings(to_plain(msg))
        want["header"]["seq"] = seq0 + k  # counted by the bridge's publisher
        assert to_plain(cls().deserialize(bytes.fromhex(data))) == want


# -- bad input: one line each, and everything goes on ------------------------------------------


def test_bad_input_is_one_line_each_and_the_bridge_goes_on(world):
    """Samples that do not decode (both ways), a type the subscriber's does not map to, a QoS
    that cannot match, a ROS 2 publisher killed: each is one line in the bridge's log, said
    once however often it happens, and the bridge keeps bridging."""
    agent, ros1, w, bridge = world["agent"], world["ros1"], world["w"], world["bridge"]
    string_md5 = "992ce8a1687cec8c8bd883ec73ca41d1"
    # ROS 1 -> ROS 2: bytes that are not a std_msgs/String
    agent("sub", id="bad1", topic="/bad_in", type=STRING, qos={"depth": 100})
    ros1("pub", id="bad1", topic="/bad_in", type="std_msgs/String", md5=string_md5,
         definition="string data\n")
    bridged(world, "/bad_in ROS 1 -> ROS 2")
    good = cdr_string("fine")[4:].hex()
    ros1("publish", id="bad1", hex=["ffffff7f00", "0100", good], wait_for=1)
    out = bridge.read_until("do not convert to std_msgs/msg/String", 10)
    assert agent("received", id="bad1", count=1, timeout=10)["items"][-1:] == ["fine"]
    # ROS 2 -> ROS 1: samples that are not CDR of the type
    ros1("sub", id="bad2", topic="/bad_out", type="std_msgs/String")
    agent("pub", id="bad2", topic="/bad_out", type=STRING, qos={"depth": 100})
    bridged(world, "/bad_out ROS 2 -> ROS 1")
    assert ros1("sub_connections", ids=["bad2"], timeout=20)["counts"]["bad2"] == 1
    agent("counts", ids=["bad2"], timeout=20)
    agent("publish_raw", id="bad2", hex=["000100000a000000ab", "00010000ffffff7f", "0001"])
    agent("publish", id="bad2", count=1, prefix="still")
    out += bridge.read_until("do not decode as std_msgs/msg/String", 10)
    got = ros1("received", id="bad2", count=1, timeout=10)
    assert [bytes.fromhex(h)[4:].decode() for h in got["items"]] == ["still 0"]
    # a ROS 2 subscriber of another type: no mapping, one line
    agent("sub", id="mismatch", topic="/mismatch", type="std_msgs/msg/Int32")
    ros1("pub", id="mismatch", topic="/mismatch", type="std_msgs/String", md5=string_md5,
         definition="string data\n")
    out += bridge.read_until("ROS 2 subscribes to std_msgs/msg/Int32", 10)
    # a QoS that cannot match: a subscriber asking for a deadline the bridge does not offer
    agent("sub", id="deadline", topic="/bad_in", type=STRING, qos={"deadline": 0.5})
    out += bridge.read_until("QoS cannot match", 10)
    # a ROS 2 publisher that vanishes (SIGKILL; its lease made 2 s by a Fast DDS profile)
    profile = w.tmp / "short_lease.xml"
    profile.write_text(SHORT_LEASE)
    doomed = w.rclpy(world["distro"], "doomed", env={"FASTRTPS_DEFAULT_PROFILES_FILE": str(profile),
                                                     "FASTDDS_DEFAULT_PROFILES_FILE": str(profile)})
    ros1("sub", id="doomed", topic="/doomed", type="std_msgs/String")
    doomed("pub", id="d", topic="/doomed", type=STRING)
    bridged(world, "/doomed ROS 2 -> ROS 1")
    assert ros1("sub_connections", ids=["doomed"], timeout=20)["counts"]["doomed"] == 1
    doomed("counts", ids=["d"], timeout=20)
    doomed("publish", id="d", count=1, prefix="last words")
    assert ros1("received", id="doomed", count=1, timeout=10)["count"] == 1
    doomed.proc.kill()
    doomed.proc.wait(5)
    out += bridge.read_until("stopped bridging /doomed ROS 2 -> ROS 1", 30)
    # the rest: still bridged, the graphs still answer
    ros1("publish", id="bad1", hex=[cdr_string("after all that")[4:].hex()])
    assert agent("received", id="bad1", count=2, timeout=10)["items"][-1] == "after all that"
    assert ["ros_bridge", "/"] in agent("graph")["nodes"]
    ros1("publish", id="bad1", hex=["ffffff7f00"] * 5)
    agent("publish_raw", id="bad2", hex=["0001"] * 5)
    ros1("publish", id="bad1", hex=[cdr_string("end")[4:].hex()])
    assert agent("received", id="bad1", count=3, timeout=10)["items"][-1] == "end"
    out += drain(bridge, 1.0)  # what the bridge said since, repeated faults included
    assert "is gone" in out  # the DDS layer's line for the peer, with its lease
    for needle in ("do not convert to std_msgs/msg/String", "do not decode as std_msgs/msg/String",
                   "ROS 2 subscribes to std_msgs/msg/Int32", "QoS cannot match"):
        assert out.count(needle) == 1, (needle, out)
    assert "Traceback" not in out


SHORT_LEASE = """<?xml version="1.0" encoding="UTF-8"?>
<profiles xmlns="http://www.eprosima.com/XMLSchemas/fastRTPS_Profiles">
  <participant profile_name="short_lease" is_default_profile="true">
    <rtps>
      <builtin>
        <discovery_config>
          <leaseDuration><sec>2</sec></leaseDuration>
          <leaseAnnouncement><nanosec>500000000</nanosec></leaseAnnouncement>
        </discovery_config>
      </builtin>
    </rtps>
  </participant>
</profiles>
"""


def test_a_best_effort_ros2_publisher_is_heard_best_effort(world):
    """rclpy's sensor-data publisher (best effort) would not match a reliable reader: the
    bridge's subscription asks for best effort, and ROS 1 hears it."""
    agent, ros1 = world["agent"], world["ros1"]
    ros1("sub", id="be", topic="/scan_like", type="std_msgs/String")
    agent("pub", id="be", topic="/scan_like", type=STRING,
          qos={"reliability": "best_effort", "depth": 5})
    bridged(world, "/scan_like ROS 2 -> ROS 1")
    subscriptions = wait_for(lambda: [s for s in agent("graph", topic="/scan_like")
                                      ["subscriptions"] if s["node"] == "ros_bridge"],
                             10, "the bridge's subscription")
    assert [(s["reliability"], s["durability"], s["hash"]) for s in subscriptions] == \
        [("BEST_EFFORT", "VOLATILE", HASHES[STRING])]
    assert ros1("sub_connections", ids=["be"], timeout=20)["counts"]["be"] == 1
    deadline = time.monotonic() + 20
    while not ros1("received", id="be", count=1, timeout=0.1)["count"]:
        assert time.monotonic() < deadline, "nothing reached ROS 1"
        agent("publish", id="be", count=1, prefix="scan")
    agent("destroy", id="be")


def test_1080p_images_both_ways(world):
    """sensor_msgs/Image 1920x1080 rgb8 (6 MB, a hundred RTPS fragments) from a minros ROS 1
    publisher to rclpy and from rclpy to a minros ROS 1 subscriber, every frame intact; the
    ROS 1 side's Header seq counted by the bridge."""
    agent, ros1 = world["agent"], world["ros1"]
    image = "sensor_msgs/msg/Image"
    agent("sub", id="img", topic="/camera_in", type=image, qos={"depth": 10})
    ros1("publish_images", id="cam", topic="/camera_in", count=0)
    bridged(world, "/camera_in ROS 1 -> ROS 2")
    assert ros1("pub_connections", ids=["cam"], timeout=20)["counts"]["cam"] == 1
    assert agent("counts", ids=["img"], timeout=20)["counts"]["img"] == 1
    sent = ros1("publish_images", id="cam", count=5, rate=10)["md5"]
    got = agent("received", id="img", count=5, timeout=30)["items"]
    assert [(x["width"], x["height"], x["encoding"], x["md5"]) for x in got] == \
        [(1920, 1080, "rgb8", md5) for md5 in sent]
    ros1("image_sub", id="view", topic="/camera_out")
    agent("pub", id="cam2", topic="/camera_out", type=image, qos={"depth": 10})
    bridged(world, "/camera_out ROS 2 -> ROS 1")
    assert ros1("sub_connections", ids=["view"], timeout=20)["counts"]["view"] == 1
    agent("counts", ids=["cam2"], timeout=20)
    sent = agent("publish", id="cam2", image=True, count=5, rate=10)["md5"]
    got = ros1("images", id="view", count=5, timeout=30)["items"]
    assert [tuple(x) for x in got] == [(1920, 1080, "rgb8", i + 1, md5)
                                       for i, md5 in enumerate(sent)]


# -- the graphs ---------------------------------------------------------------------------------


def test_the_bridge_is_a_ros1_node_rosnode_info_lists_its_topics(world):
    """After the latched test: the bridge subscribes to /latched_state (ROS 1 -> ROS 2) and
    publishes /ros2_latched (ROS 2 -> ROS 1), as Debian's rosnode says."""
    require_reference()
    out = world["w"].run_in(["/usr/bin/rosnode", "info", "/ros_bridge"], timeout=30,
                            reference=True)
    assert out.returncode == 0, out.stderr
    text = out.stdout
    assert "Node [/ros_bridge]" in text
    publications = text.split("Publications:", 1)[1].split("Subscriptions:", 1)[0]
    subscriptions = text.split("Subscriptions:", 1)[1].split("Services:", 1)[0]
    assert "/ros2_latched [std_msgs/String]" in publications
    assert "/latched_state [std_msgs/String]" in subscriptions


if __name__ == "__main__":  # pragma: no cover
    sys.exit(pytest.main([__file__, "-q"]))
