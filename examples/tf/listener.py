#!/usr/bin/env python3
"""A tf2 listener: where is the moon seen from the earth, and the earth seen from the moon?

    python examples/tf/listener.py [--count N]

A tf2_ros.Buffer fed by a TransformListener (a /tf and /tf_static subscriber) answers
lookup_transform; the inverse direction is computed from the same stored transform.
"""

import argparse
import math

import rospy
import tf2_ros


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--count", type=int, default=0, help="exit after N lookups (0: never)")
    args = parser.parse_args(rospy.myargv()[1:])
    rospy.init_node("moon_listener")
    buffer = tf2_ros.Buffer()
    tf2_ros.TransformListener(buffer)
    rate = rospy.Rate(2)
    done = 0
    while not rospy.is_shutdown() and (not args.count or done < args.count):
        try:
            moon = buffer.lookup_transform("earth", "moon", rospy.Time(0), rospy.Duration(2.0))
            earth = buffer.lookup_transform("moon", "earth", rospy.Time(0))
        except (tf2_ros.LookupException, tf2_ros.ConnectivityException,
                tf2_ros.ExtrapolationException) as exc:
            rospy.logwarn("no transform yet: %s", exc)
            rate.sleep()
            continue
        m, e = moon.transform.translation, earth.transform.translation
        rospy.loginfo("moon from earth: (%.2f, %.2f), %.2f m; earth from moon: (%.2f, %.2f)",
                      m.x, m.y, math.hypot(m.x, m.y), e.x, e.y)
        done += 1
        rate.sleep()


if __name__ == "__main__":
    try:
        main()
    except rospy.ROSInterruptException:
        pass
