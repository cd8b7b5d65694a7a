"""The rospy topic API in one minros process: publish forms, AnyMsg, SubscribeListener,
wait_for_message, get_published_topics, unregister, connection headers, Header auto-fill."""

from __future__ import annotations

from pathlib import Path

import pytest

from support import PYTHON, Proc, ros_env

SCRIPT = r'''
import threading, warnings
import rospy
from std_msgs.msg import String, Header, ColorRGBA
from geometry_msgs.msg import PointStamped

def check(label, cond):
    print(("OK " if cond else "FAIL ") + label, flush=True)

with warnings.catch_warnings(record=True) as caught:
    warnings.simplefilter("always")
    sync = rospy.Publisher("/sync", String)
check("queue_size=None warns SyntaxWarning", any(w.category is SyntaxWarning for w in caught))
try:
    sync.publish("x")
    check("publish before init_node raises", False)
except rospy.ROSException as e:
    check("publish before init_node raises", "init_node" in str(e))

rospy.init_node("api")

# --- publish(msg | *args | **kwargs), headers and _connection_header
got = []
event = threading.Event()
def on_color(m):
    got.append((m.r, m.g, m.b, m.a, m._connection_header.get("extra")))
    if len(got) == 3:
        event.set()
pub = rospy.Publisher("/color", ColorRGBA, queue_size=10, headers={"extra": "yes"})
sub = rospy.Subscriber("/color", ColorRGBA, on_color)
while pub.get_num_connections() == 0:
    rospy.sleep(0.01)
pub.publish(ColorRGBA(1, 2, 3, 4))
pub.publish(5, 6, 7, 8)
pub.publish(r=9, a=1)
event.wait(5)
check("publish forms", got == [(1, 2, 3, 4, "yes"), (5, 6, 7, 8, "yes"), (9, 0, 0, 1, "yes")])
try:
    pub.publish(1, r=2)
    check("args and kwargs together rejected", False)
except TypeError:
    check("args and kwargs together rejected", True)

# --- Header auto-fill: seq from 1 per publisher, frame_id None -> "0", stamp untouched
stamped = []
hev = threading.Event()
def on_stamped(m):
    stamped.append((m.header.seq, m.header.frame_id, m.header.stamp.secs))
    if len(stamped) == 2:
        hev.set()
spub = rospy.Publisher("/stamped", PointStamped, queue_size=10)
ssub = rospy.Subscriber("/stamped", PointStamped, on_stamped)
while spub.get_num_connections() == 0:
    rospy.sleep(0.01)
m = PointStamped()
m.header.frame_id = None
m.header.stamp = rospy.Time(42, 0)
spub.publish(m)
check("seq written back into the message", m.header.seq == 1)
m2 = PointStamped()
m2.header.seq = 99
spub.publish(m2)
hev.wait(5)
check("header seq/frame_id", stamped == [(1, "0", 42), (2, "", 0)])

# --- AnyMsg receives raw bytes; wait_for_message; SubscribeListener
class Listener(rospy.SubscribeListener):
    def __init__(self):
        self.events = []
        self.ev = threading.Event()
    def peer_subscribe(self, topic, topic_publish, peer_publish):
        self.events.append(("sub", topic))
        peer_publish(String("just for you"))
    def peer_unsubscribe(self, topic, num_peers):
        self.events.append(("unsub", topic, num_peers))
        self.ev.set()
listener = Listener()
lpub = rospy.Publisher("/listened", String, queue_size=10, subscriber_listener=listener)
raw = rospy.wait_for_message("/listened", rospy.AnyMsg, timeout=5)
check("AnyMsg raw bytes", bytes(raw._buff) == b"\x0c\x00\x00\x00just for you")
listener.ev.wait(5)
check("SubscribeListener events", listener.events == [("sub", "/listened"), ("unsub", "/listened", 0)])
try:
    rospy.wait_for_message("/nobody", String, timeout=0.2)
    check("wait_for_message timeout", False)
except rospy.ROSException as e:
    check("wait_for_message timeout", "timeout exceeded" in str(e))

topics = rospy.get_published_topics()
check("get_published_topics", ["/color", "std_msgs/ColorRGBA"] in topics)

# --- unregister: no longer published, publish raises
pub.unregister()
check("unregistered publisher gone", ["/color", "std_msgs/ColorRGBA"] not in rospy.get_published_topics())
try:
    pub.publish(ColorRGBA())
    check("publish after unregister raises", False)
except rospy.ROSException:
    check("publish after unregister raises", True)
sub.unregister()
sub.unregister()  # a second call is harmless
check("subscriber unregistered", ["/color", "std_msgs/ColorRGBA"] not in
      [[t, ty] for t, ty in rospy.get_master().getSystemState()[2][1]])
print("ALL DONE", flush=True)
'''


@pytest.mark.smoke
def test_topic_api(tmp_path: Path, minros_master, ros_home):
    script = tmp_path / "api.py"
    script.write_text(SCRIPT)
    proc = Proc([PYTHON, str(script)], ros_env(minros_master, ros_home))
    out = proc.read_until("ALL DONE", 30)
    proc.stop()
    failures = [line for line in out.splitlines() if line.startswith("FAIL")]
    assert not failures, out
    assert len([line for line in out.splitlines() if line.startswith("OK ")]) == 13, out


ZERO_COPY = r'''
import threading, time
import rospy
from rospy.numpy_msg import numpy_msg
from sensor_msgs.msg import Image
got = []
event = threading.Event()
rospy.init_node("zero_copy")
pub = rospy.Publisher("/frames", Image, queue_size=2)
rospy.Subscriber("/frames", numpy_msg(Image), lambda m: (got.append(m), event.set()))
while pub.get_num_connections() == 0:
    time.sleep(0.01)
pub.publish(Image(height=1080, width=1920, encoding="bgr8", step=5760,
                  data=bytes(range(256)) * (1920 * 1080 * 3 // 256)))
event.wait(10)
data = got[0].data
# the array is a view of the very buffer the socket was read into: no copy on the way
print("RESULT", type(data).__name__, data.nbytes, int(data[257]),
      type(data.base).__name__, type(data.base.obj).__name__, flush=True)
'''


def test_large_frames_reach_numpy_msg_without_copies(tmp_path: Path, minros_master, ros_home):
    """Over TCPROS (MINROS_SHM=0: shared memory reads in place anyway, test_shm_run.py)."""
    script = tmp_path / "zero_copy.py"
    script.write_text(ZERO_COPY)
    proc = Proc([PYTHON, str(script)], ros_env(minros_master, ros_home, {"MINROS_SHM": "0"}))
    out = proc.read_until("RESULT", 30)
    proc.stop()
    assert "RESULT ndarray 6220800 1 memoryview bytearray" in out
