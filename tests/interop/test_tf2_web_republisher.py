"""tf2_web_republisher with its real clients through `minros web`: roslib's TFClient (npm,
the TFSubscription action) and roslibpy's TFClient (PyPI, the republish_tfs service and its
latched TFArray topic). Transforms come from Debian's static_transform_publisher and a Debian
rospy broadcaster moving a frame 2 cm per step at 20 Hz; the clients get the static frame
as published and the moving one only after it moved more than the 0.1 m threshold."""

from __future__ import annotations

import json
import shutil
import subprocess
import threading
import time
from pathlib import Path

import pytest

from support import (
    PYTHON,
    REFERENCE_PYTHON,
    Proc,
    free_port,
    need,
    reference_env,
    require_tf_reference,
    ros_env,
)

pytestmark = pytest.mark.interop

ROSRUN = str(Path(PYTHON).parent / "rosrun")
JS = Path(__file__).resolve().parent.parent / "web" / "js"

MOVER = r'''
import rospy, tf2_ros
from geometry_msgs.msg import TransformStamped
rospy.init_node("mover")
br = tf2_ros.TransformBroadcaster()
rate = rospy.Rate(20)
x = 0.0
while not rospy.is_shutdown():
    t = TransformStamped()
    t.header.stamp = rospy.Time.now()
    t.header.frame_id = "base_link"
    t.child_frame_id = "moving"
    t.transform.translation.x = x
    t.transform.rotation.w = 1.0
    br.sendTransform(t)
    x += 0.02
    rate.sleep()
'''


def _check(got: dict) -> None:
    assert got["arm"], got
    assert [round(v, 4) for v in got["arm"][-1]] == [1.0, 2.0, 0.0, 0.0, 0.0, 0.7071, 0.7071]
    xs = [m[0] for m in got["moving"]]
    assert len(xs) >= 3, got
    steps = [b - a for a, b in zip(xs, xs[1:])]
    # each update moved more than the 0.1 m threshold (the mover makes 0.02 m steps)
    assert all(step > 0.1 - 1e-9 for step in steps), xs


def test_roslib_and_roslibpy_tfclients(tmp_path: Path, debian_rosmaster: int,
                                       ros_home: Path) -> None:
    require_tf_reference()
    env = ros_env(debian_rosmaster, ros_home)
    denv = reference_env(env)
    mover_script = tmp_path / "mover.py"
    mover_script.write_text(MOVER)
    web_port = free_port()
    procs = [
        Proc(["/usr/lib/tf2_ros/static_transform_publisher", "1", "2", "0", "0", "0",
              "0.7071068", "0.7071068", "base_link", "arm"], denv),
        Proc([REFERENCE_PYTHON, str(mover_script)], denv),
        Proc([ROSRUN, "tf2_web_republisher", "tf2_web_republisher"], env),
        Proc([PYTHON, "-m", "minros", "web", "--port", str(web_port)], env),
    ]
    url = f"ws://127.0.0.1:{web_port}"
    try:
        import roslibpy
        import roslibpy.tf

        deadline = time.monotonic() + 30
        ros = roslibpy.Ros("127.0.0.1", web_port)
        while True:
            try:
                ros.run(timeout=5)
                break
            except Exception:  # noqa: BLE001 - minros web still starting
                if time.monotonic() > deadline:
                    raise
                time.sleep(0.5)
        # the service path (roslibpy)
        got = {"arm": [], "moving": []}
        lock = threading.Lock()
        tf = roslibpy.tf.TFClient(ros, fixed_frame="base_link", angular_threshold=0.01,
                                  translation_threshold=0.1, rate=10.0)
        for frame in got:
            def record(msg, frame=frame):
                t, r = msg["translation"], msg["rotation"]
                with lock:
                    got[frame].append([t["x"], t["y"], t["z"], r["x"], r["y"], r["z"], r["w"]])
            tf.subscribe(frame, record)
        time.sleep(4.0)
        with lock:
            _check(got)
        ros.terminate()

        # the action path (roslib in node)
        need(shutil.which("node") is not None and (JS / "node_modules" / "roslib").is_dir(),
             "node and tests/web/js/node_modules (npm ci) are needed for roslib")
        done = subprocess.run(["node", str(JS / "tfclient.mjs"), url, "4"], capture_output=True,
                              text=True, timeout=60)
        assert done.returncode == 0, done.stdout + done.stderr
        _check(json.loads(done.stdout.split("RESULT ", 1)[1].splitlines()[0]))
    finally:
        for proc in reversed(procs):
            proc.stop()
