"""``rosbag convert`` against the real things: a bag recorded live from ``minros sim``, the
turtlesim tutorial and a talker of CameraInfo and a custom message type, converted to ROS 2
and decoded by the pip rclpy (Jazzy, Kilted: one process each), its type hashes against
rosidl's JSON (or rosidl's own generator, for types the wheels lack), its CDR bytes against
rosbags-convert's; converted back and read by Debian's rosbag; a rosbag2 of rclpy-serialized
messages played by minros into Debian's rospy.
"""

from __future__ import annotations

import json
import math
import os
import subprocess
import time
from pathlib import Path

import pytest

from minros.bag import Bag
from minros.ros2.types import Mapper
from minros.ros2.types.registry import SHARE
from minros.ros2.types.testing import (
    ROS2_HOME,
    oracle_available,
    oracle_python,
    plain,
    rclpy_check,
    ros2_plain_of_ros1,
    rosidl_hashes,
)
from ros2bag_support import (
    CUSTOM_DEFINITION,
    CUSTOM_TYPE,
    PLAIN_SOURCE,
    load_metadata,
    rosbag2_messages,
)
from sim_support import Sim
from support import (
    PYTHON,
    REFERENCE_PYTHON,
    Proc,
    need,
    reference_env,
    require_reference,
    ros_env,
)

pytestmark = [pytest.mark.interop, pytest.mark.timeout(600)]  # the recording, two rclpy runs

HERE = Path(__file__).resolve().parent
TALKER = HERE / "ros2bag_talker.py"
TOPICS = ["/odom", "/scan", "/tf", "/tf_static", "/sim/view", "/joint_states", "/map",
          "/turtle1/pose", "/turtle1/color_sensor", "/turtle1/cmd_vel", "/camera/camera_info",
          "/status", "/rosout"]
DISTROS = ["jazzy", "kilted"]


def require_ros2(distro: str) -> None:
    need(oracle_available(distro), f"the pip ROS 2 {distro} is not installed",
         "scripts/install-ros2-reference.sh")


def minros_bag(*argv: str, timeout: float = 300) -> subprocess.CompletedProcess:
    return subprocess.run([PYTHON, "-m", "minros", "bag", *argv], capture_output=True, text=True,
                          timeout=timeout)


@pytest.fixture(scope="module")
def recording(tmp_path_factory) -> Path:
    """A bag of ``minros sim`` (odometry, scans, TF, the top-down Image, joint states, the
    map), turtlesim driven as its tutorial does (rostopic pub on /turtle1/cmd_vel), the
    CameraInfo and custom-type talker, and rosout: ``rosbag record`` for 4 s."""
    home = tmp_path_factory.mktemp("ros2bag_home")
    (home / "log").mkdir()
    folder = tmp_path_factory.mktemp("ros2bag")
    sim = Sim(home, "--view-rate", "2")
    procs = []
    try:
        env = dict(sim.env, MINROS_HEADLESS="1")
        turtle = Proc([PYTHON, "-m", "minros", "run", "turtlesim", "turtlesim_node"], env)
        procs.append(turtle)
        turtle.read_until("Spawning turtle [turtle1]", timeout=30)
        talker = Proc([PYTHON, str(TALKER)], sim.env)
        procs.append(talker)
        talker.read_until("READY", timeout=30)
        procs.append(Proc([PYTHON, "-m", "minros", "topic", "pub", "-r", "10", "/turtle1/cmd_vel",
                           "geometry_msgs/Twist", "--", "[2.0, 0.0, 0.0]", "[0.0, 0.0, 1.8]"],
                          sim.env))
        record = Proc([PYTHON, "-m", "minros", "bag", "record", "-O", str(folder / "sim.bag"),
                       *TOPICS], sim.env)
        try:
            record.read_until("Recording to", timeout=30)
            time.sleep(4.0)  # the length of the recording (minros's --duration splits only)
        finally:
            out = record.stop(timeout=30)
        assert "Traceback" not in out, out
    finally:
        for proc in procs:
            proc.stop()
        sim.stop()
    path = folder / "sim.bag"
    with Bag(str(path)) as bag:
        counts = {t: bag.get_message_count(t) for t in TOPICS}
    assert all(counts.values()), counts  # every kind was recorded
    return path


def ros1_messages(path: Path) -> dict:
    """topic -> (ROS 1 type, [messages]) read with minros's Bag API."""
    out: dict = {}
    with Bag(str(path)) as bag:
        for topic, msg, _t in bag.read_messages():
            out.setdefault(topic, (msg._type, []))[1].append(msg)
    return out


def mapper_for(distro: str) -> Mapper:
    mapper = Mapper(distro)
    mapper.add_ros1_definition(CUSTOM_TYPE, CUSTOM_DEFINITION)
    return mapper


def same(a, b) -> bool:
    """Plain values equal, NaN equal to NaN."""
    if isinstance(a, dict) and isinstance(b, dict):
        return a.keys() == b.keys() and all(same(a[k], b[k]) for k in a)
    if isinstance(a, list) and isinstance(b, list):
        return len(a) == len(b) and all(same(x, y) for x, y in zip(a, b))
    if isinstance(a, float) and isinstance(b, float) and math.isnan(a) and math.isnan(b):
        return True
    return a == b


def share_hash(distro: str, ros2_type: str):
    pkg, _ns, name = ros2_type.split("/")
    path = ROS2_HOME / distro / "share" / pkg / "msg" / f"{name}.json"
    if not path.exists():
        return None
    data = json.loads(path.read_text())
    return next(h["hash_string"] for h in data["type_hashes"] if h["type_name"] == ros2_type)


@pytest.mark.parametrize("distro", DISTROS)
def test_recording_converts_and_rclpy_decodes_it(recording, tmp_path, distro):
    require_ros2(distro)
    out = tmp_path / "ros2"
    result = minros_bag("convert", str(recording), str(out), "--distro", distro)
    assert result.returncode == 0, result.stderr
    assert result.stderr == ""  # every topic converted
    meta = load_metadata(out)
    assert meta["version"] == 9 and meta["ros_distro"] == distro
    stored = rosbag2_messages(out)
    ros1 = ros1_messages(recording)
    assert set(stored) == set(ros1) == set(TOPICS)
    mapper = mapper_for(distro)

    # every topic's type hash: rosidl's JSON in the pip ROS 2, or rosidl's generator run on
    # the definitions (tf2_msgs, turtlesim and the custom type are not in the wheels)
    hashes = {t["topic_metadata"]["type"]: t["topic_metadata"]["type_description_hash"]
              for t in meta["topics_with_message_count"]}
    missing = {}
    for ros2_type, digest in hashes.items():
        theirs = share_hash(distro, ros2_type)
        if theirs is None:
            missing.setdefault(ros2_type.split("/")[0], []).append(ros2_type)
        else:
            assert digest == theirs, ros2_type
    assert set(missing) == {"tf2_msgs", "turtlesim", "my_robot_msgs"}
    packages = {pkg: [(p.parent.name, p.stem, p.read_text())
                      for p in sorted((SHARE / distro / pkg).glob("msg/*.msg"))]
                for pkg in ("tf2_msgs", "turtlesim")}
    made = mapper.ros2
    mapper.message(CUSTOM_TYPE)
    packages["my_robot_msgs"] = [("msg", made.message(n).short_name, made.message(n).text)
                                 for n in ("my_robot_msgs/msg/Wheel", "my_robot_msgs/msg/Status")]
    generated = rosidl_hashes(distro, packages)
    for names in missing.values():
        for ros2_type in names:
            assert hashes[ros2_type] == generated[ros2_type], ros2_type

    # every message: rclpy's deserialize_message gives what the ROS 1 message said (types
    # the wheels ship); the others, rosbags' CDR reader with the stored definition
    requests, expected, others = [], [], []
    for topic, (ros2_type, _digest, datas) in sorted(stored.items()):
        ros1_type, msgs = ros1[topic]
        mapping = mapper.message(ros1_type)
        assert mapping.ros2_type == ros2_type
        assert len(datas) == len(msgs)
        for msg, data in zip(msgs, datas):
            want = ros2_plain_of_ros1(mapping, msg)
            if share_hash(distro, ros2_type) is not None:
                requests.append((ros2_type, data))
                expected.append((topic, want))
            else:
                others.append((topic, ros2_type, data, want))
    results = rclpy_check(distro, requests)
    decoded = {}
    for (topic, want), got in zip(expected, results):
        assert "error" not in got, (topic, got.get("error"))
        assert same(got["plain"], want), topic
        decoded[topic] = decoded.get(topic, 0) + 1
    assert {"/odom", "/scan", "/sim/view", "/camera/camera_info", "/joint_states", "/map",
            "/turtle1/cmd_vel", "/rosout"} <= set(decoded)
    from rosbags.rosbag2 import Reader
    from rosbags.typesys import Stores, get_types_from_msg, get_typestore

    store = get_typestore(Stores.EMPTY)
    with Reader(out) as reader:
        for conn in reader.connections:
            if conn.msgtype.split("/")[0] in missing:
                store.register(get_types_from_msg(conn.msgdef.data, conn.msgtype))
    for topic, ros2_type, data, want in others:
        got = plain(mapper.ros2, ros2_type, store.deserialize_cdr(data, ros2_type))
        if ros2_type == "my_robot_msgs/msg/Status":  # rosbags reads ROS 2's byte (an octet,
            got["blob"] = [b & 0xFF for b in got["blob"]]  # 0..255 in rclpy) as int8
        assert same(got, want), topic


@pytest.mark.parametrize("distro", DISTROS)
def test_cdr_bytes_equal_rosbags_convert(recording, tmp_path, distro):
    """rosbags-convert (its command) on the same bag: byte-equal CDR and equal type hashes for
    every type its typestore knows; it copies the others from the bag (and says so)."""
    ours, theirs = tmp_path / "ours", tmp_path / "theirs"
    assert minros_bag("convert", "-q", str(recording), str(ours), "--distro", distro) \
        .returncode == 0
    tool = Path(PYTHON).parent / "rosbags-convert"
    result = subprocess.run([str(tool), "--src", str(recording), "--dst", str(theirs),
                             "--dst-storage", "mcap", "--dst-typestore", f"ros2_{distro}"],
                            capture_output=True, text=True, timeout=300)
    assert result.returncode == 0, result.stdout + result.stderr
    copied = {line.split("'")[1] for line in result.stdout.splitlines()
              if line.startswith("Missing msgtype in destination")}
    # rosgraph_msgs/Log: ROS 2 has rcl_interfaces/msg/Log (ros1_bridge's rule, minros's choice)
    assert copied == {"my_robot_msgs/msg/Status", "turtlesim/msg/Pose", "turtlesim/msg/Color",
                      "rosgraph_msgs/msg/Log"}
    a, b = rosbag2_messages(ours), rosbag2_messages(theirs)
    compared = 0
    for topic, (ros2_type, digest, datas) in a.items():
        their_type, their_digest, their_datas = b[topic]
        if their_type != ros2_type or ros2_type in copied:
            continue
        assert digest == their_digest, topic
        assert datas == their_datas, topic
        compared += 1
    assert compared >= 9


def test_back_to_ros1_reads_under_debians_rosbag(recording, tmp_path):
    """Converted to ROS 2 and back, the bag reads under Debian's rosbag with the types, md5
    sums and values of the recording; Header seq, which ROS 2 lacks, is named in the plan
    and counted from 1."""
    require_reference()
    ros2, back = tmp_path / "ros2", tmp_path / "back.bag"
    there = minros_bag("convert", str(recording), str(ros2))
    assert there.returncode == 0, there.stderr
    # the fields ROS 2 lacks, as the plan names them: "without header.seq; without topics"
    lacking = {}
    for line in there.stdout.splitlines():
        if line.startswith("  /") and "(" in line:
            notes = line.rsplit("(", 1)[1].rstrip(")").split("; ")
            lacking[line.split()[0]] = [n[len("without "):] for n in notes
                                        if n.startswith("without ")]
    assert lacking["/rosout"] == ["header.seq", "header.frame_id", "topics"]
    assert lacking["/tf"] == ["transforms[].header.seq"]
    result = minros_bag("convert", str(ros2), str(back))
    assert result.returncode == 0, result.stderr
    plan = {line.split()[0]: line for line in result.stdout.splitlines()
            if line.startswith("  /")}
    for topic in ("/odom", "/scan", "/sim/view", "/camera/camera_info", "/status", "/map"):
        assert "(header.seq counted from 1" in plan[topic], plan[topic]
    assert "header.seq" not in plan["/turtle1/pose"]
    script = tmp_path / "read.py"
    script.write_text(PLAIN_SOURCE + r'''
import json, sys, rosbag
out = {}
with rosbag.Bag(sys.argv[1]) as bag:
    conns = {}
    for c in bag._get_connections():
        text = lambda v: v.decode() if isinstance(v, bytes) else v
        conns.setdefault(c.topic, []).append([c.datatype, c.md5sum,
                                              text(c.header.get("callerid")),
                                              text(c.header.get("latching"))])
    for topic, msg, t in bag.read_messages():
        out.setdefault(topic, []).append([t.to_nsec(), msg._type, msg._md5sum, plain(msg)])
print(json.dumps({"conns": conns, "messages": out}))
''')

    def debian(path: Path) -> dict:
        run = subprocess.run([REFERENCE_PYTHON, str(script), str(path)], env=reference_env({}),
                             capture_output=True, text=True, timeout=300)
        assert run.returncode == 0, run.stderr
        return json.loads(run.stdout)

    before, after = debian(recording), debian(back)
    # types, md5 sums and latching as recorded; a topic with several publishers is one topic
    # in ROS 2, so one connection (the first publisher's callerid) comes back
    assert set(after["conns"]) == set(before["conns"])
    for topic, conns in before["conns"].items():
        (back_conn,) = after["conns"][topic]
        assert back_conn in conns, topic
    assert set(after["messages"]) == set(TOPICS)
    for topic, msgs in before["messages"].items():
        got = after["messages"][topic]
        assert [m[:3] for m in got] == [m[:3] for m in msgs], topic
        named = lacking.get(topic, [])
        for m in got:  # what ROS 2 lacks comes back empty (seq: counted, below)
            for path in named:
                if path != "header.seq":
                    assert all(v in (0, "", []) for v in values_at(m[3], path)), (topic, path)
        assert same([blank(m[3], named) for m in got], [blank(m[3], named) for m in msgs]), topic
        if "header.seq" in named:
            assert [m[3]["header"]["seq"] for m in got] == list(range(1, len(got) + 1))


def values_at(value, path: str) -> list:
    """The values at a field path of a plain message (``transforms[].header.seq``)."""
    head, _, rest = path.partition(".")
    name = head.rstrip("[]")
    inner = value[name]
    items = inner if head.endswith("[]") else [inner]
    return [v for item in items for v in (values_at(item, rest) if rest else [item])]


def blank(value, paths):
    """A plain message with the fields at ``paths`` set to None."""
    import copy

    value = copy.deepcopy(value)
    for path in paths:
        parts = path.split(".")
        targets = [value]
        for part in parts[:-1]:
            name = part.rstrip("[]")
            targets = [t[name] for t in targets]
            if part.endswith("[]"):
                targets = [item for t in targets for item in t]
        for t in targets:
            t[parts[-1]] = None
    return value


LISTENER = r'''
import json, sys
import rospy
from nav_msgs.msg import Odometry
from sensor_msgs.msg import Image
from std_msgs.msg import String

want = int(sys.argv[1])
got = []

def keep(kind):
    def cb(msg):
        if kind == "chatter":
            got.append([kind, msg.data])
        elif kind == "odom":
            got.append([kind, msg.header.seq, msg.header.stamp.secs, msg.header.stamp.nsecs,
                        msg.header.frame_id, msg.child_frame_id, msg.pose.pose.position.x,
                        list(msg.pose.covariance[:3]), msg.twist.twist.angular.z])
        else:
            got.append([kind, msg.header.seq, msg.height, msg.width, msg.encoding, msg.step,
                        list(bytearray(msg.data))])
        if len(got) >= want:
            rospy.signal_shutdown("done")
    return cb

rospy.init_node("ros2_bag_listener")
rospy.Subscriber("/chatter", String, keep("chatter"))
rospy.Subscriber("/odom", Odometry, keep("odom"))
rospy.Subscriber("/camera/image", Image, keep("image"))
print("READY", flush=True)
rospy.Timer(rospy.Duration(60), lambda _e: rospy.signal_shutdown("timeout"), oneshot=True)
rospy.spin()
print("RESULT " + json.dumps(got), flush=True)
'''

RCLPY_WRITER = r'''
import json
from builtin_interfaces.msg import Time
from nav_msgs.msg import Odometry
from rclpy.serialization import serialize_message
from sensor_msgs.msg import Image
from std_msgs.msg import String

out = []
for i in range(3):
    stamp = Time(sec=1700000000 + i, nanosec=250000000)
    out.append(["/chatter", "std_msgs/msg/String", serialize_message(String(data=f"from rclpy {i}")).hex()])
    odom = Odometry(child_frame_id="base_link")
    odom.header.stamp, odom.header.frame_id = stamp, "odom"
    odom.pose.pose.position.x = 1.5 * i
    odom.pose.covariance[:3] = [0.1, 0.2, 0.3]
    odom.twist.twist.angular.z = -0.5
    out.append(["/odom", "nav_msgs/msg/Odometry", serialize_message(odom).hex()])
    img = Image(height=2, width=2, encoding="mono8", step=2, data=bytes([i, 1, 2, 255]))
    img.header.stamp, img.header.frame_id = stamp, "camera"
    out.append(["/camera/image", "sensor_msgs/msg/Image", serialize_message(img).hex()])
print(json.dumps(out))
'''


def test_a_rosbag2_of_rclpy_messages_plays_into_rospy(minros_core, ros_home, tmp_path):
    """Messages serialized by rclpy (the pip Jazzy), in a rosbag2 written with rosbags'
    Writer as rclpy-side tools do, played by ``minros bag play`` on a minros master: Debian's
    rospy receives them as ROS 1 messages with the values rclpy gave."""
    require_ros2("jazzy")
    require_reference()
    from rosbags.rosbag2 import Writer
    from rosbags.typesys import Stores, get_typestore

    env = {k: v for k, v in os.environ.items() if not k.startswith(("ROS_", "AMENT_", "RMW_"))}
    made = subprocess.run([str(oracle_python("jazzy")), "-c", RCLPY_WRITER], env=env,
                          capture_output=True, text=True, timeout=120)
    assert made.returncode == 0, made.stderr
    store = get_typestore(Stores.ROS2_JAZZY)
    rec = tmp_path / "from_rclpy"
    with Writer(rec, version=9) as writer:
        conns = {}
        for i, (topic, ros2_type, data) in enumerate(json.loads(made.stdout)):
            if topic not in conns:
                conns[topic] = writer.add_connection(topic, ros2_type, typestore=store)
            writer.write(conns[topic], 1_700_000_000 * 10**9 + i * 10_000_000, bytes.fromhex(data))
    script = tmp_path / "listen.py"
    script.write_text(LISTENER)
    listener = Proc([REFERENCE_PYTHON, str(script), "9"],
                    reference_env(ros_env(minros_core, ros_home)))
    try:
        listener.read_until("READY", timeout=30)
        play = subprocess.run([PYTHON, "-m", "minros", "bag", "play", "--wait-for-subscribers",
                               "-d", "0.5", str(rec)], env=ros_env(minros_core, ros_home),
                              capture_output=True, text=True, timeout=90)
        assert play.returncode == 0, play.stdout + play.stderr
        out = listener.read_until("RESULT ", timeout=60)
    finally:
        listener.stop()
    got = json.loads(out.split("RESULT ", 1)[1].splitlines()[0])
    assert sorted(g[1] for g in got if g[0] == "chatter") == [f"from rclpy {i}" for i in range(3)]
    odom = sorted((g for g in got if g[0] == "odom"), key=lambda g: g[1])
    assert odom == [["odom", i + 1, 1700000000 + i, 250000000, "odom", "base_link", 1.5 * i,
                     [0.1, 0.2, 0.3], -0.5] for i in range(3)]
    images = sorted((g for g in got if g[0] == "image"), key=lambda g: g[1])
    assert images == [["image", i + 1, 2, 2, "mono8", 2, [i, 1, 2, 255]] for i in range(3)]


def test_damaged_recording_one_line_from_the_commands(recording, tmp_path, minros_core,
                                                     ros_home):
    """The commands as a user runs them: one line on stderr, no traceback, status 1."""
    rec = tmp_path / "rec"
    assert minros_bag("convert", "-q", "--topic", "/odom", str(recording), str(rec)).returncode == 0
    mcap = rec / "rec.mcap"
    mcap.write_bytes(mcap.read_bytes()[:-100])
    for argv in (["bag", "info", str(rec)], ["bag", "play", str(rec)],
                 ["topic", "echo", "-b", str(rec), "/odom"],
                 ["bag", "convert", str(rec), str(tmp_path / "back.bag")]):
        run = subprocess.run([PYTHON, "-m", "minros", *argv], capture_output=True, text=True,
                             timeout=60, env=ros_env(minros_core, ros_home))
        assert run.returncode == 1, (argv, run.stdout, run.stderr)
        lines = [x for x in run.stderr.splitlines() if x.strip()]
        assert len(lines) == 1 and "Traceback" not in run.stderr, (argv, run.stderr)
        assert f"{mcap} is cut short" in lines[0], (argv, lines)
