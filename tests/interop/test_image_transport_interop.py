"""image_transport republish (raw <-> compressed) between Debian's rospy and cv_bridge: a
Debian publisher's bgr8 frames come out JPEG-compressed with compressed_image_transport's
format string and decode in Debian's cv_bridge to nearly the same picture; frames that
Debian's cv_bridge compressed come out raw."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from support import PYTHON, REFERENCE_PYTHON, Proc, need, reference_env, reference_imports, ros_env

pytestmark = pytest.mark.interop

ROSRUN = str(Path(PYTHON).parent / "rosrun")

PROBE = r'''
import json, time
import numpy as np
import rospy
from cv_bridge import CvBridge
from sensor_msgs.msg import Image, CompressedImage
rospy.init_node("image_probe")
bridge = CvBridge()
frame = np.zeros((120, 160, 3), np.uint8)
frame[:, :, 0] = np.arange(160, dtype=np.uint8)[None, :]
frame[:, :, 1] = np.arange(120, dtype=np.uint8)[:, None] * 2
frame[:, :, 2] = 90
got = {}

def on_compressed(msg):
    img = bridge.compressed_imgmsg_to_cv2(msg)
    got["compressed"] = [msg.format, list(img.shape), float(np.abs(img.astype(int) - frame).mean())]

def on_raw(msg):
    img = bridge.imgmsg_to_cv2(msg)
    got["raw"] = [msg.encoding, list(img.shape), float(np.abs(img.astype(int) - frame).mean())]

rospy.Subscriber("/cam/repub/compressed", CompressedImage, on_compressed)
rospy.Subscriber("/cam2/raw", Image, on_raw)
raw_pub = rospy.Publisher("/cam/image", Image, queue_size=1)
jpeg_pub = rospy.Publisher("/cam2/image/compressed", CompressedImage, queue_size=1)
deadline = time.time() + 40
while len(got) < 2 and time.time() < deadline:
    msg = bridge.cv2_to_imgmsg(frame, "bgr8")
    msg.header.stamp = rospy.Time.now()
    raw_pub.publish(msg)
    jpeg_pub.publish(bridge.cv2_to_compressed_imgmsg(frame))  # format "jpeg"
    time.sleep(0.2)
print("GOT " + json.dumps(got), flush=True)
'''


def test_republish_raw_and_compressed(tmp_path: Path, debian_rosmaster: int, ros_home: Path) -> None:
    need(reference_imports("cv_bridge, numpy"), "Debian's python3-cv-bridge is not installed",
         "scripts/install-ros-reference.sh")
    env = ros_env(debian_rosmaster, ros_home)
    denv = reference_env(env)
    script = tmp_path / "probe.py"
    script.write_text(PROBE)
    procs = [
        Proc([ROSRUN, "image_transport", "republish", "raw", "in:=/cam/image", "compressed",
              "out:=/cam/repub"], env),
        Proc([ROSRUN, "image_transport", "republish", "compressed", "in:=/cam2/image", "raw",
              "out:=/cam2/raw"], env),
    ]
    try:
        probe = Proc([REFERENCE_PYTHON, str(script)], denv)
        procs.append(probe)
        out = probe.read_until("GOT ", 60)
        got = json.loads(out.split("GOT ", 1)[1].splitlines()[0])
        fmt, shape, diff = got["compressed"]
        assert fmt == "bgr8; jpeg compressed bgr8" and shape == [120, 160, 3] and diff < 4, got
        encoding, shape, diff = got["raw"]
        assert encoding == "bgr8" and shape == [120, 160, 3] and diff < 4, got
    finally:
        for proc in reversed(procs):
            proc.stop()


def test_republish_usage_errors() -> None:
    import subprocess

    done = subprocess.run([ROSRUN, "image_transport", "republish", "theora", "in:=/a"],
                          capture_output=True, text=True, timeout=60)
    assert done.returncode == 1 and "theora and compressedDepth are not available" in done.stderr
    assert "Traceback" not in done.stderr
