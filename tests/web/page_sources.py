"""Test-only publishers for the web page's browser tests (one node, what the options ask for).

    page_sources.py [--image HZ] [--signal HZ] [--imshow] [--logs] [--log-burst N]

--image HZ      a 640x480 bgr8 sensor_msgs/Image on /camera/image_raw (a moving gradient)
--signal HZ     a std_msgs/Float64 sine on /signal (1 kHz for the plot's performance test)
--imshow        cv2.imshow("page test", ...) once a second (headless OpenCV: /imshow/page_test)
--logs          one line at each level (debug to fatal) every half second, through rosout
--log-burst N   N rosgraph_msgs/Log lines straight onto /rosout_agg, as fast as possible,
                then "BURST DONE" on stdout

Prints "READY" once its publishers are registered.
"""

from __future__ import annotations

import argparse
import math
import threading
import time

import numpy as np

import rospy
from rosgraph_msgs.msg import Log
from sensor_msgs.msg import Image
from std_msgs.msg import Float64


def frames(count: int = 30) -> list:
    ys, xs = np.mgrid[0:480, 0:640]
    out = []
    for i in range(count):
        frame = np.empty((480, 640, 3), dtype=np.uint8)
        frame[:, :, 0] = (xs + i * 20) % 256
        frame[:, :, 1] = (ys * 255 // 480).astype(np.uint8)
        frame[:, :, 2] = 128
        out.append(frame)
    return out


def every(period: float, step, stop: threading.Event) -> None:
    """Call step(n) every ``period`` seconds on a fixed schedule (no drift)."""
    next_time = time.monotonic()
    n = 0
    while not stop.is_set() and not rospy.is_shutdown():
        step(n)
        n += 1
        next_time += period
        delay = next_time - time.monotonic()
        if delay > 0:
            stop.wait(delay)
        elif delay < -0.5:
            next_time = time.monotonic()


def main() -> None:
    parser = argparse.ArgumentParser()
    parser.add_argument("--image", type=float, default=0)
    parser.add_argument("--signal", type=float, default=0)
    parser.add_argument("--imshow", action="store_true")
    parser.add_argument("--logs", action="store_true")
    parser.add_argument("--log-burst", type=int, default=0)
    args = parser.parse_args(rospy.myargv()[1:])
    rospy.init_node("page_sources")
    stop = threading.Event()
    threads = []

    def start(target, *a) -> None:
        thread = threading.Thread(target=target, args=a, daemon=True)
        thread.start()
        threads.append(thread)

    if args.image:
        from cv_bridge import CvBridge

        image_pub = rospy.Publisher("/camera/image_raw", Image, queue_size=2)
        bridge = CvBridge()
        messages = [bridge.cv2_to_imgmsg(f, "bgr8") for f in frames()]

        def send_image(n: int) -> None:
            msg = messages[n % len(messages)]
            msg.header.stamp = rospy.Time.now()
            image_pub.publish(msg)
        start(every, 1.0 / args.image, send_image, stop)
    if args.signal:
        signal_pub = rospy.Publisher("/signal", Float64, queue_size=1000)
        start(every, 1.0 / args.signal,
              lambda n: signal_pub.publish(Float64(math.sin(n / args.signal * 2 * math.pi))), stop)
    if args.imshow:
        import cv2

        picture = frames(1)[0]

        def show(n: int) -> None:
            cv2.imshow("page test", np.roll(picture, n * 10, axis=1))
        start(every, 1.0, show, stop)
    if args.logs:
        def log(n: int) -> None:
            rospy.logdebug(f"debug line {n}")
            rospy.loginfo(f"info line {n}")
            rospy.logwarn(f"warn line {n}")
            rospy.logerr(f"error line {n}")
            rospy.logfatal(f"fatal line {n}")
        start(every, 0.5, log, stop)
    burst_pub = rospy.Publisher("/rosout_agg", Log, queue_size=args.log_burst + 10) if args.log_burst else None
    print("READY", flush=True)
    if burst_pub is not None:
        deadline = time.monotonic() + 20
        while burst_pub.get_num_connections() == 0 and time.monotonic() < deadline:
            time.sleep(0.05)  # until minros web's console has subscribed
        levels = [Log.DEBUG, Log.INFO, Log.WARN, Log.ERROR, Log.FATAL]
        for n in range(args.log_burst):
            msg = Log(level=levels[n % 5], name="/burst", msg=f"burst line {n}", file="page_sources.py",
                      function="main", line=n)
            msg.header.stamp = rospy.Time.now()
            burst_pub.publish(msg)
        print("BURST DONE", flush=True)
    try:
        rospy.spin()
    finally:
        stop.set()


if __name__ == "__main__":
    main()
