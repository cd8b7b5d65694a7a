"""Node scripts shared by the publish/subscribe tests (minros and Debian rospy run the same text).

They use only the rospy API, so the identical file runs under minros (``import rospy`` is the
stand-in) and under Debian's rospy; tests write them to a temporary directory.
"""

TALKER = r'''
import sys
import rospy
from std_msgs.msg import String
from geometry_msgs.msg import PointStamped
from sensor_msgs.msg import Image

topic, kind, count, hz, latch = sys.argv[1], sys.argv[2], int(sys.argv[3]), float(sys.argv[4]), sys.argv[5] == "1"
queue = None if len(sys.argv) > 6 and sys.argv[6] == "none" else 10
cls = {"string": String, "stamped": PointStamped, "image": Image}[kind]
pub = rospy.Publisher(topic, cls, queue_size=queue, latch=latch)
rospy.init_node("talker", anonymous=True)


def make(i):
    if kind == "string":
        return String("msg %d" % i)
    if kind == "stamped":
        m = PointStamped()
        m.header.stamp = rospy.Time(1000 + i, 5)
        m.header.frame_id = "map"
        m.header.seq = 777  # overwritten by the publisher's counter
        m.point.x = float(i)
        return m
    m = Image()
    m.height, m.width, m.encoding, m.step = 1080, 1920, "bgr8", 1920 * 3
    m.header.frame_id = "cam"
    m.data = bytes([i % 251]) * (1920 * 1080 * 3)
    return m


if latch:
    pub.publish(make(0))
    print("published latched", flush=True)
    rospy.spin()
else:
    while pub.get_num_connections() == 0 and not rospy.is_shutdown():
        rospy.sleep(0.01)
    print("subscriber connected", flush=True)
    rate = rospy.Rate(hz)
    for i in range(count):
        pub.publish(make(i))
        rate.sleep()
    print("sent %d" % count, flush=True)
    rospy.spin()
'''

LISTENER = r'''
import hashlib
import sys
import rospy
from std_msgs.msg import String
from geometry_msgs.msg import PointStamped
from sensor_msgs.msg import Image

topic, kind, count = sys.argv[1], sys.argv[2], int(sys.argv[3])
cls = {"string": String, "stamped": PointStamped, "image": Image}[kind]
seen = []


def callback(m):
    who = m._connection_header["callerid"].split("_")[0]
    if kind == "string":
        line = "got %s from %s" % (m.data, who)
    elif kind == "stamped":
        line = "got seq=%d stamp=%d.%d frame=%s x=%g" % (
            m.header.seq, m.header.stamp.secs, m.header.stamp.nsecs, m.header.frame_id, m.point.x)
    else:
        data = bytes(m.data)
        line = "got seq=%d %dx%d %s len=%d first=%d md5=%s" % (
            m.header.seq, m.width, m.height, m.encoding, len(data), data[0],
            hashlib.md5(data).hexdigest()[:12])
    print(line, flush=True)
    seen.append(line)
    if len(seen) >= count:
        rospy.signal_shutdown("done")


rospy.init_node("listener", anonymous=True)
rospy.Subscriber(topic, cls, callback)
print("subscribed", flush=True)
rospy.spin()
print("listener done %d" % len(seen), flush=True)
'''
