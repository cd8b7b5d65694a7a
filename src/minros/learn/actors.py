"""The small nodes ``minros learn`` starts: ``python -m minros.learn.actors ROLE [options]``.

Each is plain rospy code, as a learner would write it:

    talker          publishes "hello world N" (std_msgs/String) at --rate Hz
    listener        subscribes a std_msgs/String topic
    temperature     publishes sensor_msgs/Temperature once a second (--frame-id, --value, ...)
    stale_listener  subscribes with a std_msgs/String built from an older definition
    once            publishes one std_msgs/String at start, latched or not (--latch 1|0)
    add_server      serves add_two_ints (rospy_tutorials/AddTwoInts)
    flood           publishes --size byte strings at --rate Hz (400: Nagle's stall)
    relay_out       subscribes a topic and writes each message to stdout (one JSON line)
    relay_in        reads those lines from stdin and publishes them on its own master

``relay_out`` and ``relay_in`` are the two halves of a relay between two masters: one node
on each (each process is one node, on the master its ROS_MASTER_URI names), joined by a pipe.
"""

from __future__ import annotations

import argparse
import base64
import json
import sys
import threading
from typing import List, Optional

import rospy


def _talker(args: argparse.Namespace) -> None:
    from std_msgs.msg import String

    rospy.init_node(args.name or "talker")
    pub = rospy.Publisher(args.topic, String, queue_size=10)
    rate = rospy.Rate(args.rate)
    count = 0
    while not rospy.is_shutdown():
        pub.publish(String(f"hello world {count}"))
        count += 1
        rate.sleep()


def _listener(args: argparse.Namespace) -> None:
    from std_msgs.msg import String

    rospy.init_node(args.name or "listener")
    rospy.Subscriber(args.topic, String, lambda msg: None)
    rospy.spin()


def _temperature(args: argparse.Namespace) -> None:
    from sensor_msgs.msg import Temperature

    rospy.init_node(args.name or "thermometer")
    pub = rospy.Publisher("temperature", Temperature, queue_size=10)
    rate = rospy.Rate(args.rate)
    while not rospy.is_shutdown():
        msg = Temperature(temperature=args.value, variance=args.variance)
        msg.header.stamp = rospy.Time.now()
        msg.header.frame_id = args.frame_id
        pub.publish(msg)
        rate.sleep()


def _stale_listener(args: argparse.Namespace) -> None:
    from minros.msgs import generate_dynamic

    # what an old build of std_msgs/String would be: same name, another definition
    old = generate_dynamic("std_msgs/String", "int32 data")["std_msgs/String"]
    rospy.init_node(args.name or "old_listener")
    rospy.Subscriber(args.topic, old, lambda msg: None)
    rospy.spin()


def _once(args: argparse.Namespace) -> None:
    from std_msgs.msg import String

    name = args.name or args.topic.strip("/") + "_sensor"
    rospy.init_node(name)
    pub = rospy.Publisher(args.topic, String, queue_size=1, latch=args.latch == "1")
    pub.publish(String(f"{args.topic.strip('/')}: open"))
    rospy.spin()


def _add_server(args: argparse.Namespace) -> None:
    from rospy_tutorials.srv import AddTwoInts, AddTwoIntsResponse

    rospy.init_node(args.name or "add_two_ints_server")
    rospy.Service("add_two_ints", AddTwoInts, lambda req: AddTwoIntsResponse(req.a + req.b))
    rospy.spin()


def _flood(args: argparse.Namespace) -> None:
    from std_msgs.msg import String

    rospy.init_node(args.name or "sensor")
    pub = rospy.Publisher(args.topic, String, queue_size=100)
    rate = rospy.Rate(args.rate)
    payload = "x" * args.size
    while not rospy.is_shutdown():
        pub.publish(String(payload))
        rate.sleep()


def _relay_out(args: argparse.Namespace) -> None:
    rospy.init_node(args.name or "relay")
    out = sys.stdout
    lock = threading.Lock()

    def forward(msg: rospy.AnyMsg) -> None:
        header = getattr(msg, "_connection_header", None) or {}
        line = json.dumps({"type": header.get("type", ""),
                           "definition": header.get("message_definition", ""),
                           "data": base64.b64encode(bytes(msg._buff)).decode()})
        with lock:
            try:
                out.write(line + "\n")
                out.flush()
            except (BrokenPipeError, ValueError):  # the other half ended
                rospy.signal_shutdown("the relay's other half ended")

    rospy.Subscriber(args.topic, rospy.AnyMsg, forward)
    rospy.spin()


def _relay_in(args: argparse.Namespace) -> None:
    from minros.msgs import generate_dynamic

    rospy.init_node(args.name or "relay")
    pub: Optional[rospy.Publisher] = None
    cls = None
    for line in sys.stdin:
        if rospy.is_shutdown():
            break
        item = json.loads(line)
        if pub is None:
            cls = generate_dynamic(item["type"], item["definition"])[item["type"]]
            pub = rospy.Publisher(args.topic, cls, queue_size=10)
        pub.publish(cls().deserialize(base64.b64decode(item["data"])))


ROLES = {"talker": _talker, "listener": _listener, "temperature": _temperature,
         "stale_listener": _stale_listener, "once": _once, "add_server": _add_server,
         "flood": _flood, "relay_out": _relay_out, "relay_in": _relay_in}


def main(argv: Optional[List[str]] = None) -> int:
    parser = argparse.ArgumentParser(prog="python -m minros.learn.actors",
                                     description="The nodes minros learn starts.")
    parser.add_argument("role", choices=sorted(ROLES))
    parser.add_argument("--name", default="", help="the node's name")
    parser.add_argument("--topic", default="/chatter")
    parser.add_argument("--rate", type=float, default=0.0, help="messages per second")
    parser.add_argument("--frame-id", default="kitchen")
    parser.add_argument("--value", type=float, default=21.5)
    parser.add_argument("--variance", type=float, default=0.5)
    parser.add_argument("--latch", choices=("0", "1"), default="0")
    parser.add_argument("--size", type=int, default=1000, help="bytes of each flood message")
    args = parser.parse_args(argv)
    if not args.rate:
        args.rate = {"talker": 2.0, "temperature": 1.0, "flood": 400.0}.get(args.role, 1.0)
    try:
        ROLES[args.role](args)
    except rospy.ROSInterruptException:
        pass
    return 0


if __name__ == "__main__":
    sys.exit(main())
