"""Publish at a fixed rate for the CLI throughput measurements (minros).

usage: cli_rate_pub.py small|image RATE_HZ [SECONDS]
small: std_msgs/String "msg N" ; image: sensor_msgs/Image 1920x1080 rgb8 (6.2 MB) with header.
Prints "ready" then, at the end, "sent N".
"""

import sys
import time

import rospy
from sensor_msgs.msg import Image
from std_msgs.msg import String


def main():
    kind, rate = sys.argv[1], float(sys.argv[2])
    seconds = float(sys.argv[3]) if len(sys.argv) > 3 else 1e9
    rospy.init_node(f"rate_pub_{kind}")
    if kind == "image":
        pub = rospy.Publisher("/image", Image, queue_size=2)
        msg = Image(height=1080, width=1920, encoding="rgb8", step=1920 * 3, data=bytes(1920 * 1080 * 3))
    else:
        pub = rospy.Publisher("/fast", String, queue_size=1000)
        msg = String()
    print("ready", flush=True)
    period = 1.0 / rate
    start = time.monotonic()
    next_t = start
    n = 0
    while not rospy.is_shutdown() and time.monotonic() - start < seconds:
        n += 1
        if kind == "image":
            msg.header.stamp = rospy.Time.now()
        else:
            msg.data = f"msg {n}"
        pub.publish(msg)
        next_t += period
        delay = next_t - time.monotonic()
        if delay > 0:
            time.sleep(delay)
    print(f"sent {n}", flush=True)
    rospy.signal_shutdown("done")


if __name__ == "__main__":
    main()
