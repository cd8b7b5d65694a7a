"""minros <-> Debian rospy on Debian's rosmaster: strings, latched, Header-stamped, 1080p images."""

from __future__ import annotations

import hashlib
from pathlib import Path

import pytest

from integration.pubsub_scripts import LISTENER, TALKER
from support import PYTHON, REFERENCE_PYTHON, Proc, reference_env, require_reference, ros_env

pytestmark = pytest.mark.interop


def _run(impl: str, script: Path, args, port: int, home: Path) -> Proc:
    env = ros_env(port, home)
    if impl == "rospy":
        return Proc([REFERENCE_PYTHON, str(script), *map(str, args)], reference_env(env))
    return Proc([PYTHON, str(script), *map(str, args)], env)


@pytest.fixture
def scripts(tmp_path: Path):
    require_reference()
    talker = tmp_path / "talker.py"
    listener = tmp_path / "listener.py"
    talker.write_text(TALKER)
    listener.write_text(LISTENER)
    return talker, listener


def _exchange(scripts, port, home, pub_impl, sub_impl, kind, count, hz=50, latch=False, extra=()):
    talker, listener = scripts
    procs = []
    try:
        if latch:
            pub = _run(pub_impl, talker, [f"/lt_{kind}", kind, 1, hz, 1, *extra], port, home)
            procs.append(pub)
            pub.read_until("published latched", 20)
            sub = _run(sub_impl, listener, [f"/lt_{kind}", kind, count], port, home)
        else:
            sub = _run(sub_impl, listener, [f"/t_{kind}", kind, count], port, home)
            procs.append(sub)
            sub.read_until("subscribed", 20)
            pub = _run(pub_impl, talker, [f"/t_{kind}", kind, count, hz, 0, *extra], port, home)
        procs.append(pub)
        out = sub.read_until(f"listener done {count}", 30)
        return [line for line in out.splitlines() if line.startswith("got ")]
    finally:
        for proc in procs:
            proc.stop()


PAIRS = [("minros", "rospy"), ("rospy", "minros")]


@pytest.mark.parametrize("pub_impl, sub_impl", PAIRS)
def test_strings_in_order(scripts, debian_rosmaster, ros_home, pub_impl, sub_impl):
    got = _exchange(scripts, debian_rosmaster, ros_home, pub_impl, sub_impl, "string", 20)
    assert got == [f"got msg {i} from /talker" for i in range(20)]


@pytest.mark.parametrize("pub_impl, sub_impl", PAIRS)
def test_synchronous_publisher(scripts, debian_rosmaster, ros_home, pub_impl, sub_impl):
    got = _exchange(scripts, debian_rosmaster, ros_home, pub_impl, sub_impl, "string", 10,
                    extra=("none",))
    assert got == [f"got msg {i} from /talker" for i in range(10)]


@pytest.mark.smoke
@pytest.mark.parametrize("pub_impl, sub_impl", PAIRS)
def test_latched_message_reaches_late_subscriber(scripts, debian_rosmaster, ros_home, pub_impl, sub_impl):
    got = _exchange(scripts, debian_rosmaster, ros_home, pub_impl, sub_impl, "string", 1, latch=True)
    assert got == ["got msg 0 from /talker"]


@pytest.mark.parametrize("pub_impl, sub_impl", PAIRS)
def test_header_seq_filled_stamp_kept(scripts, debian_rosmaster, ros_home, pub_impl, sub_impl):
    got = _exchange(scripts, debian_rosmaster, ros_home, pub_impl, sub_impl, "stamped", 5)
    # seq counts from 1 per publisher (the 777 set by the script is overwritten); stamp untouched
    assert got == [f"got seq={i + 1} stamp={1000 + i}.5 frame=map x={i}" for i in range(5)]


@pytest.mark.parametrize("pub_impl, sub_impl", PAIRS)
def test_1080p_images(scripts, debian_rosmaster, ros_home, pub_impl, sub_impl):
    got = _exchange(scripts, debian_rosmaster, ros_home, pub_impl, sub_impl, "image", 4, hz=10)
    size = 1920 * 1080 * 3
    expected = [
        f"got seq={i + 1} 1920x1080 bgr8 len={size} first={i} "
        f"md5={hashlib.md5(bytes([i]) * size).hexdigest()[:12]}"
        for i in range(4)
    ]
    assert got == expected


MISMATCH_SUB = r'''
import rospy
from std_msgs.msg import Int32
rospy.init_node("typed_sub", anonymous=True)
rospy.Subscriber("/typed", Int32, lambda m: print("UNEXPECTED", m, flush=True))
print("subscribed", flush=True)
rospy.spin()
'''

MISMATCH_PUB = r'''
import rospy
from std_msgs.msg import String
rospy.init_node("typed_pub", anonymous=True)
pub = rospy.Publisher("/typed", String, queue_size=1)
print("publishing", flush=True)
while not rospy.is_shutdown():
    pub.publish("text")
    rospy.sleep(0.05)
'''


@pytest.mark.parametrize("pub_impl, sub_impl", PAIRS)
def test_type_mismatch_reported_on_both_sides(tmp_path, debian_rosmaster, ros_home, pub_impl, sub_impl):
    require_reference()
    pub_script = tmp_path / "pub.py"
    sub_script = tmp_path / "sub.py"
    pub_script.write_text(MISMATCH_PUB)
    sub_script.write_text(MISMATCH_SUB)
    sub = _run(sub_impl, sub_script, [], debian_rosmaster, ros_home)
    pub = _run(pub_impl, pub_script, [], debian_rosmaster, ros_home)
    try:
        sub.read_until("subscribed", 20)
        pub.read_until("publishing", 20)
        expected = "topic types do not match: [std_msgs/Int32] vs. [std_msgs/String]"
        # the publisher refuses the connection and says why in its log...
        pub.read_until(f"Could not process inbound connection: {expected}", 15)
        if sub_impl == "minros":  # ...and the subscriber shows the error the publisher sent
            sub.read_until(f"remote error reported: {expected}", 15)
    finally:
        sub_out = sub.stop()
        pub.stop()
    assert "UNEXPECTED" not in sub_out
