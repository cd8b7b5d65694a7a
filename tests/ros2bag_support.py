"""Test helpers for ROS 1 <-> ROS 2 bag conversion: sample bags, plain values, the readers.

``plain`` reduces a ROS 1 message (minros's or genpy's) to dicts, lists, numbers and strings,
so that minros's and Debian's readings compare; ``PLAIN_SOURCE`` is the same function as text,
for scripts run by Debian's Python.
"""

from __future__ import annotations

import inspect
import io
import json
import math
from pathlib import Path
from typing import Any, Dict, List, Tuple

#: a ROS 1 package nobody installed: upper-case field names, constants, byte[], time, char,
#: a nested type of its own and a fixed array of it
CUSTOM_TYPE = "my_robot_msgs/Status"
CUSTOM_DEFINITION = """\
# the status of one robot
Header header
uint8 MODE_IDLE=0
uint8 MODE_DRIVE=1
uint8 Mode
string Name
byte[] blob
char letter
time last_seen
duration uptime
my_robot_msgs/Wheel[2] wheels
float32[] temperatures
================================================================================
MSG: std_msgs/Header
uint32 seq
time stamp
string frame_id
================================================================================
MSG: my_robot_msgs/Wheel
float64 Speed
int8 id
"""

def plain(value):
    """A ROS 1 message as dicts, lists and numbers (bytes as lists of ints, times as pairs)."""
    slots = getattr(value, "__slots__", None)
    if slots is not None and hasattr(value, "_slot_types"):
        return {name: plain(getattr(value, name)) for name in slots}
    if hasattr(value, "secs") and hasattr(value, "nsecs"):
        return [int(value.secs), int(value.nsecs)]
    if isinstance(value, (bytes, bytearray)):
        return list(value)
    if isinstance(value, (list, tuple)):
        return [plain(v) for v in value]
    return value


#: plain() as text, for scripts Debian's Python runs
PLAIN_SOURCE = inspect.getsource(plain)


def custom_classes() -> Dict[str, Any]:
    from minros.msgs import generate_dynamic

    return generate_dynamic(CUSTOM_TYPE, CUSTOM_DEFINITION)


def sample_messages() -> List[Tuple[str, Any, int]]:
    """(topic, ROS 1 message, time ns) of every kind the conversion tests cover."""
    import minros
    from geometry_msgs.msg import Quaternion, TransformStamped, Twist, Vector3
    from nav_msgs.msg import Odometry
    from sensor_msgs.msg import CameraInfo, Image, LaserScan, Range
    from std_msgs.msg import String
    from tf2_msgs.msg import TFMessage

    classes = custom_classes()
    Status, Wheel = classes[CUSTOM_TYPE], classes["my_robot_msgs/Wheel"]
    out: List[Tuple[str, Any, int]] = []
    t0 = 1_700_000_000 * 10**9
    for i in range(4):
        t = t0 + i * 100_000_000
        stamp = minros.Time(t // 10**9, t % 10**9)
        img = Image(height=2, width=3, encoding="rgb8", step=9, data=bytes(range(i, i + 18)))
        img.header.seq, img.header.stamp, img.header.frame_id = 10 + i, stamp, "camera"
        out.append(("/camera/image", img, t))
        info = CameraInfo(height=480, width=640, distortion_model="plumb_bob")
        info.header.stamp, info.header.frame_id = stamp, "camera"
        info.D = [0.1 * i, -0.2, 0.001, 0.0, 0.0]
        info.K = [500.0, 0, 320, 0, 500.0, 240, 0, 0, 1]
        info.P = [500.0, 0, 320, 0, 0, 500.0, 240, 0, 0, 0, 1, 0]
        info.roi.do_rectify = bool(i % 2)
        out.append(("/camera/camera_info", info, t))
        scan = LaserScan(angle_min=-math.pi, angle_max=math.pi, angle_increment=math.pi / 4,
                         range_min=0.12, range_max=3.5,
                         ranges=[float("inf"), 1.0 + i, 2.5, 0.5, 3.0, 1.25, 2.0, 0.75],
                         intensities=[100.0] * 8)
        scan.header.stamp, scan.header.frame_id = stamp, "base_scan"
        out.append(("/scan", scan, t))
        odom = Odometry(child_frame_id="base_footprint")
        odom.header.stamp, odom.header.frame_id = stamp, "odom"
        odom.pose.pose.position.x = 0.5 * i
        odom.pose.pose.orientation.w = 1.0
        odom.pose.covariance = [float(k) for k in range(36)]
        odom.twist.twist.linear.x = 0.22
        out.append(("/odom", odom, t))
        tf = TransformStamped()
        tf.header.stamp, tf.header.frame_id, tf.child_frame_id = stamp, "odom", "base_footprint"
        tf.transform.translation = Vector3(0.5 * i, 0.0, 0.0)
        tf.transform.rotation = Quaternion(0.0, 0.0, 0.0, 1.0)
        out.append(("/tf", TFMessage(transforms=[tf, tf]), t))
        out.append(("/chatter", String(f"hello {i}"), t))
        out.append(("/cmd_vel", Twist(linear=Vector3(0.1 * i, 0, 0)), t))
        out.append(("/range", Range(radiation_type=1, min_range=0.1, max_range=2.0,
                                    range=0.5 + i), t))
        status = Status(Mode=1, Name=f"robot{i}", blob=[1, -2, 3], letter=65,
                        last_seen=stamp, uptime=minros.Duration(-5, 10),
                        wheels=[Wheel(Speed=1.5, id=-1), Wheel(Speed=-0.25, id=2)],
                        temperatures=[20.5, 21.0])
        status.header.stamp, status.header.frame_id = stamp, "base"
        out.append(("/status", status, t))
    return out


def write_sample_bag(path: Path, latched: Tuple[str, ...] = ("/camera/camera_info",)) -> None:
    """The sample messages in a ROS 1 bag; ``latched`` topics recorded as latched."""
    import minros
    from minros.bag import Bag

    with Bag(str(path), "w") as bag:
        for topic, msg, t in sample_messages():
            header = None
            if topic in latched:
                header = {"topic": topic, "type": msg._type, "md5sum": msg._md5sum,
                          "message_definition": msg._full_text, "callerid": "/camera_node",
                          "latching": "1"}
            buff = io.BytesIO()
            msg.serialize(buff)
            bag.write(topic, (msg._type, buff.getvalue(), msg._md5sum, type(msg)),
                      minros.Time(t // 10**9, t % 10**9), raw=True, connection_header=header)


def read_plain(path: Path) -> Dict[str, List[Any]]:
    """topic -> plain values of its messages, read with minros's Bag API (any format)."""
    from minros.bag import Bag

    out: Dict[str, List[Any]] = {}
    with Bag(str(path)) as bag:
        for topic, msg, t in bag.read_messages():
            out.setdefault(topic, []).append((t.to_nsec(), msg._type, plain(msg)))
    return out


def without_seq(value: Any) -> Any:
    """``value`` with every Header's seq taken out (ROS 2 has none)."""
    if isinstance(value, dict):
        return {k: without_seq(v) for k, v in value.items()
                if not (k == "seq" and {"stamp", "frame_id"} <= set(value))}
    if isinstance(value, list):
        return [without_seq(v) for v in value]
    return value


def rosbag2_messages(path: Path) -> Dict[str, Tuple[str, str, List[bytes]]]:
    """topic -> (ROS 2 type, type hash, CDR bytes of each message), read with rosbags."""
    from rosbags.rosbag2 import Reader

    out: Dict[str, Tuple[str, str, List[bytes]]] = {}
    with Reader(path) as reader:
        for conn in reader.connections:
            out.setdefault(conn.topic, (conn.msgtype, conn.digest, []))
        for conn, _t, data in reader.messages():
            out[conn.topic][2].append(bytes(data))
    return out


def load_metadata(path: Path) -> Dict[str, Any]:
    import yaml

    return yaml.safe_load((path / "metadata.yaml").read_text())["rosbag2_bagfile_information"]


def dumps(value: Any) -> str:
    return json.dumps(value, sort_keys=True)
