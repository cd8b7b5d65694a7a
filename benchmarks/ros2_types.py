"""ROS 1 <-> CDR conversion speed: minros's generated converters beside rosbags' on the same bytes.

    .venv/bin/python benchmarks/ros2_types.py [--seconds 0.3] [--rounds 5]

For each message, the ROS 1 bytes are converted to CDR (``ros1->cdr``) and those CDR bytes
back (``cdr->ros1``) by:

* ``minros``: ``minros.ros2.types`` transcoders (``Mapper().message(t).transcoder``), generated
  per type pair; output ``bytes``;
* ``rosbags``: rosbags 0.11's ``Typestore.ros1_to_cdr`` / ``cdr_to_ros1`` (ROS 2 Jazzy store),
  which also converts bytes to bytes without message objects; output a ``memoryview``;
* ``memcpy``: ``bytes(memoryview(data))``, one copy of the input: the floor for a converter
  that returns new bytes.

Figures are MB/s of the input and microseconds per message, from the fastest ~2 ms batch of
each (minros.msgs.testing.best_rate); the contenders alternate within each round and each keeps
its best round, so all see the same machine load.
"""

from __future__ import annotations

import argparse
import io
import os
from typing import Any, Callable, Dict, List, Tuple

from minros.msgs import Time, get_message_class
from minros.msgs.testing import best_rate
from minros.ros2.types import Mapper


def cases() -> List[Tuple[str, str, bytes]]:
    def ser(msg: Any) -> bytes:
        buf = io.BytesIO()
        msg.serialize(buf)
        return buf.getvalue()

    Header = get_message_class("std_msgs/Header")
    twist = get_message_class("geometry_msgs/Twist")()
    twist.linear.x, twist.angular.z = 0.5, -0.25
    scan = get_message_class("sensor_msgs/LaserScan")(
        header=Header(seq=3, stamp=Time(1700000000, 5), frame_id="laser"),
        angle_min=-3.14, angle_max=3.14, angle_increment=0.00872, range_max=30.0,
        ranges=[1.0 + i / 720 for i in range(720)], intensities=[100.0] * 720)
    image = get_message_class("sensor_msgs/Image")(
        header=Header(seq=1, stamp=Time(5, 6), frame_id="camera"), height=1080, width=1920,
        encoding="rgb8", is_bigendian=0, step=1920 * 3, data=os.urandom(1920 * 1080 * 3))
    PointField = get_message_class("sensor_msgs/PointField")
    points = 640 * 480
    cloud = get_message_class("sensor_msgs/PointCloud2")(
        header=Header(frame_id="lidar"), height=1, width=points,
        fields=[PointField(name=n, offset=4 * i, datatype=7, count=1)
                for i, n in enumerate(("x", "y", "z", "intensity"))],
        is_bigendian=False, point_step=16, row_step=16 * points, data=os.urandom(16 * points),
        is_dense=True)
    return [
        ("String ('hello world')", "std_msgs/String",
         ser(get_message_class("std_msgs/String")(data="hello world"))),
        ("Twist", "geometry_msgs/Twist", ser(twist)),
        ("LaserScan 720 rays", "sensor_msgs/LaserScan", ser(scan)),
        ("Image 1920x1080 rgb8", "sensor_msgs/Image", ser(image)),
        ("PointCloud2 307200 pts", "sensor_msgs/PointCloud2", ser(cloud)),
    ]


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--seconds", type=float, default=0.3, help="per contender per round")
    parser.add_argument("--rounds", type=int, default=5)
    args = parser.parse_args()

    from rosbags.typesys import Stores, get_typestore

    store = get_typestore(Stores.ROS2_JAZZY)
    mapper = Mapper("jazzy")
    rows = []
    for label, ros1_type, raw in cases():
        m = mapper.message(ros1_type)
        t = m.transcoder
        cdr = t.ros1_to_cdr(raw)
        name = m.ros2_type
        # the same bytes both ways, or the comparison means nothing
        assert bytes(store.ros1_to_cdr(raw, name)) == cdr, label
        assert bytes(store.cdr_to_ros1(cdr, name)) == t.cdr_to_ros1(cdr), label
        contenders: Dict[str, Callable[[], Any]] = {
            "minros ros1->cdr": lambda raw=raw, t=t: t.ros1_to_cdr(raw),
            "rosbags ros1->cdr": lambda raw=raw, name=name: store.ros1_to_cdr(raw, name),
            "minros cdr->ros1": lambda cdr=cdr, t=t: t.cdr_to_ros1(cdr),
            "rosbags cdr->ros1": lambda cdr=cdr, name=name: store.cdr_to_ros1(cdr, name),
            "memcpy": lambda raw=raw: bytes(memoryview(raw)),
        }
        best = dict.fromkeys(contenders, 0.0)
        for _ in range(args.rounds):
            for key, fn in contenders.items():
                best[key] = max(best[key], best_rate(fn, args.seconds))
        rows.append((label, len(raw), best))

    keys = list(rows[0][2])
    print(f"ROS 1 <-> CDR conversion, MB/s of input (us/msg); {args.rounds} rounds, "
          f"best ~2 ms batch")
    head = f"{'message':24} {'bytes':>9}" + "".join(f" {k:>22}" for k in keys)
    print(head)
    print("-" * len(head))
    for label, size, best in rows:
        cells = []
        for key in keys:
            rate = best[key]
            cells.append(f"{rate * size / 1e6:10.1f} ({1e6 / rate:8.2f})")
        print(f"{label:24} {size:9d}" + "".join(f" {c:>22}" for c in cells))


if __name__ == "__main__":
    main()
