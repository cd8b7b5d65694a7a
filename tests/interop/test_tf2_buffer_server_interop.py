"""tf2's buffer server and client across implementations: Debian's C++ buffer_server asked
by minros's BufferClient, and minros's buffer_server (rosrun tf2_ros buffer_server) asked by
Debian's tf2_ros.BufferClient; the same lookups (a transform, an unknown frame, a frame that
appears while the goal waits, the advanced API) give the same answers and exceptions."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from support import (
    PYTHON,
    REFERENCE_PYTHON,
    Proc,
    need,
    reference_env,
    reference_imports,
    require_tf_reference,
    ros_env,
)

pytestmark = pytest.mark.interop

ROSRUN = str(Path(PYTHON).parent / "rosrun")
DEBIAN_BUFFER_SERVER = "/usr/lib/tf2_ros/buffer_server"

CLIENT = r'''
import json, threading, time
import rospy, tf2_ros
import tf2_py as tf2
from geometry_msgs.msg import TransformStamped
rospy.init_node("buffer_client_probe")
client = tf2_ros.BufferClient("/tf2_buffer_server")
assert client.wait_for_server(rospy.Duration(30)), "no server"
late = tf2_ros.StaticTransformBroadcaster()
out = {}

def record(key, fn):
    try:
        t = fn()
        out[key] = ["ok", t.header.frame_id, t.child_frame_id,
                    [round(v, 6) for v in (t.transform.translation.x, t.transform.translation.y,
                                           t.transform.rotation.z, t.transform.rotation.w)]]
    except tf2.TransformException as exc:
        out[key] = [type(exc).__name__]

record("plain", lambda: client.lookup_transform("base", "arm", rospy.Time(0), rospy.Duration(5)))
record("inverse", lambda: client.lookup_transform("arm", "base", rospy.Time(0)))
record("unknown", lambda: client.lookup_transform("base", "nowhere", rospy.Time(0)))
record("advanced", lambda: client.lookup_transform_full("arm", rospy.Time(0), "base", rospy.Time(0), "base"))

def publish_late():
    time.sleep(1.0)
    t = TransformStamped()
    t.header.stamp = rospy.Time.now()
    t.header.frame_id = "base"
    t.child_frame_id = "late"
    t.transform.translation.y = 2.0
    t.transform.rotation.w = 1.0
    late.sendTransform(t)

threading.Thread(target=publish_late).start()
record("waited", lambda: client.lookup_transform("base", "late", rospy.Time(0), rospy.Duration(10)))
out["can"] = [client.can_transform("base", "arm", rospy.Time(0)),
              client.can_transform("base", "nowhere", rospy.Time(0))]
print("OUT " + json.dumps(out), flush=True)
'''


def _run(tmp_path: Path, port: int, home: Path, server_side: str, client_side: str) -> dict:
    env = ros_env(port, home)
    denv = reference_env(env)
    static = Proc(["/usr/lib/tf2_ros/static_transform_publisher", "1", "0", "0",
                   "0", "0", "0.7071068", "0.7071068", "base", "arm"], denv)
    if server_side == "debian":
        server = Proc([DEBIAN_BUFFER_SERVER], denv)
    else:
        server = Proc([ROSRUN, "tf2_ros", "buffer_server"], env)
    script = tmp_path / f"client_{client_side}.py"
    script.write_text(CLIENT)
    client = Proc([REFERENCE_PYTHON if client_side == "debian" else PYTHON, str(script)],
                  denv if client_side == "debian" else env)
    try:
        out = client.read_until("OUT ", 90)
        return json.loads(out.split("OUT ", 1)[1].splitlines()[0])
    finally:
        for proc in (client, server, static):
            proc.stop()


def test_buffer_server_and_client_across_implementations(tmp_path: Path, debian_rosmaster: int,
                                                         ros_home: Path) -> None:
    require_tf_reference()
    need(Path(DEBIAN_BUFFER_SERVER).exists() and reference_imports("tf2_ros.buffer_client"),
         "Debian's tf2-tools buffer_server is not installed", "scripts/install-ros-reference.sh")
    reference = _run(tmp_path, debian_rosmaster, ros_home, "debian", "debian")
    assert reference["plain"] == ["ok", "base", "arm", [1.0, 0.0, 0.707107, 0.707107]]
    assert reference["unknown"] == ["LookupException"]
    assert reference["waited"][0] == "ok"
    ours_client = _run(tmp_path, debian_rosmaster, ros_home, "debian", "minros")
    ours_server = _run(tmp_path, debian_rosmaster, ros_home, "minros", "debian")
    assert ours_client == reference
    assert ours_server == reference
