"""``minros trace dissector``: the Lua dissector it writes, loaded by Debian's tshark, decodes
TCPROS bodies by type from the connection headers of the same capture (nested types, arrays,
strings, time, int64), services from the definitions written into it, and the ok byte.

Two captures of one scenario: the pcap ``minros trace pcap`` makes from the trace (no root),
and, as root, a real one taken by dumpcap on the loopback of a network namespace of its own
(real segmentation: a 90 kB image split over segments, 200 small frames coalesced)."""

from __future__ import annotations

import os
import shutil
import subprocess
from pathlib import Path

import pytest

from support import IN_CI, PYTHON, Proc, free_port, need, ros_env, wait_for_master

TSHARK = shutil.which("tshark") or "/usr/bin/tshark"

#: one node that publishes (latched) and subscribes to itself, serves and calls a service
SCENARIO = """
import rospy
from geometry_msgs.msg import Point, PoseStamped
from sensor_msgs.msg import Image, JointState
from std_msgs.msg import Int64
from rospy_tutorials.srv import AddTwoInts, AddTwoIntsResponse

def add(req):
    if req.a == 0:
        raise rospy.ServiceException("a must not be 0")
    return AddTwoIntsResponse(req.a + req.b)

rospy.init_node("scenario")
got = {}
burst = []
pubs = {name: rospy.Publisher(name, cls, queue_size=1, latch=True) for name, cls in (
    ("point", Point), ("pose", PoseStamped), ("joints", JointState), ("count", Int64),
    ("image", Image))}
pubs["point"].publish(Point(1.0, -2.25, 0.0))
pose = PoseStamped()
pose.header.stamp = rospy.Time(1700000000, 250000000)
pose.header.frame_id = "map"
pose.pose.position = Point(0.5, -1.5, 2.0)
pose.pose.orientation.w = 1.0
pubs["pose"].publish(pose)
pubs["joints"].publish(JointState(name=["elbow", "wrist"], position=[0.25, -0.5], velocity=[],
                                  effort=[1.5]))
pubs["count"].publish(Int64(-5000000000))
pubs["image"].publish(Image(height=300, width=300, encoding="mono8", step=300,
                            data=bytes(range(256)) * 351 + bytes(144)))
for name, pub in pubs.items():
    rospy.Subscriber(name, pub.data_class, lambda msg, name=name: got.setdefault(name, msg))
burst_pub = rospy.Publisher("burst", Point, queue_size=500)
rospy.Subscriber("burst", Point, burst.append, queue_size=500)
rospy.Service("add_two_ints", AddTwoInts, add)
rospy.wait_for_service("add_two_ints", 10)
call = rospy.ServiceProxy("add_two_ints", AddTwoInts)
assert call(4, 5).sum == 9
try:
    call(0, 1)
except rospy.ServiceException:
    pass
deadline = rospy.Time.now() + rospy.Duration(20)
while burst_pub.get_num_connections() == 0 and rospy.Time.now() < deadline:
    rospy.sleep(0.01)
for i in range(200):
    burst_pub.publish(Point(float(i), 0.0, 0.0))
while (len(got) < 5 or len(burst) < 200) and rospy.Time.now() < deadline:
    rospy.sleep(0.05)
print("received", sorted(got), len(burst), flush=True)
"""


def _tshark(lua: Path, capture: Path, *args: str) -> str:
    done = subprocess.run([TSHARK, "-X", f"lua_script:{lua}", "-r", str(capture), *args],
                          capture_output=True, text=True, timeout=120,
                          env=dict(os.environ, HOME=str(capture.parent)))
    assert done.returncode == 0, done.stderr
    assert "Lua: Error" not in done.stderr and "Lua: Error" not in done.stdout, done.stderr
    return done.stdout


def _need_tshark() -> None:
    if not os.path.exists(TSHARK):
        if IN_CI:
            pytest.fail("tshark is missing: scripts/install-ros-reference.sh installs it")
        pytest.skip("tshark is not installed (apt install tshark)")


def _section(text: str, title: str, lines: int) -> list:
    """The ``lines`` lines from the one starting with ``title`` (stripped)."""
    rows = [line.strip() for line in text.splitlines()]
    for i, row in enumerate(rows):
        if row.startswith(title):
            return rows[i:i + lines]
    raise AssertionError(f"no {title!r} in the tshark output:\n{text[:20000]}")


@pytest.fixture(scope="module")
def traced_capture(tmp_path_factory):
    """The scenario traced (whole frames up to 4 kB), its pcap and the dissector."""
    _need_tshark()
    tmp = tmp_path_factory.mktemp("dissector")
    home = tmp / "ros_home"
    (home / "log").mkdir(parents=True)
    port = free_port()
    # the TCPROS wire the dissector reads (two minros nodes would take shared memory)
    env = ros_env(port, home, {"MINROS_SHM": "0"})
    core = Proc([PYTHON, "-m", "minros", "core", "-p", str(port)], env)
    try:
        wait_for_master(port)
        trace = tmp / "scenario.jsonl"
        done = subprocess.run([PYTHON, "-m", "minros", "trace", "-o", str(trace), "--bytes",
                               "4096", "--frames", "all", "--", PYTHON, "-c", SCENARIO],
                              env=env, capture_output=True, text=True, timeout=90)
        assert done.returncode == 0 and "received" in done.stdout, done.stdout + done.stderr
    finally:
        core.stop()
    capture = tmp / "run.pcap"
    lua = tmp / "minros.lua"
    for argv in (["pcap", str(trace), "-o", str(capture)],
                 ["dissector", "-o", str(lua), str(trace)]):
        done = subprocess.run([PYTHON, "-m", "minros", "trace", *argv], env=env,
                              capture_output=True, text=True, timeout=60)
        assert done.returncode == 0, done.stderr
    assert "rospy_tutorials/AddTwoInts" in done.stdout  # found in the trace, written in
    return lua, capture


def test_a_point_is_decoded_field_by_field(traced_capture):
    lua, capture = traced_capture
    out = _tshark(lua, capture, "-V")
    assert _section(out, "TCPROS message 1: geometry_msgs/Point, 24 bytes", 7)[4:] == [
        "x: 1.0", "y: -2.25", "z: 0.0"]
    # the header that told the dissector the type, field by field (the connections' order in
    # the capture varies: /rosout's may come first)
    rows = [line.strip() for line in out.splitlines()]
    headers = [rows[i:i + 8] for i, row in enumerate(rows)
               if row.startswith("TCPROS connection header (server)")]
    assert any("callerid=/scenario" in header and "latching=1" in header
               and "type=geometry_msgs/Point" in header for header in headers), headers


def test_nested_types_time_strings_arrays_and_int64(traced_capture):
    lua, capture = traced_capture
    out = _tshark(lua, capture, "-O", "minros", "-Y", "minros")
    pose = _section(out, "TCPROS message 1: geometry_msgs/PoseStamped, 75 bytes", 20)
    assert pose[4:16] == ["header", "seq: 1", "stamp: 1700000000.250000000",
                          "secs: 1700000000", "nsecs: 250000000", 'frame_id: "map"', "pose",
                          "position", "x: 0.5", "y: -1.5", "z: 2.0", "orientation"]
    joints = _section(out, "TCPROS message 1: sensor_msgs/JointState", 30)
    assert 'name: ["elbow", "wrist"]' in joints and '[1]: "wrist"' in joints
    assert "position: [0.25, -0.5]" in joints and "velocity: []" in joints
    assert "effort: [1.5]" in joints
    assert _section(out, "TCPROS message 1: std_msgs/Int64", 5)[4] == "data: -5000000000"


def test_a_frame_the_trace_cut_is_decoded_as_far_as_it_goes(traced_capture):
    lua, capture = traced_capture
    out = _tshark(lua, capture, "-O", "minros", "-Y", "minros")
    image = _section(out, "TCPROS message 1: sensor_msgs/Image, 90042 bytes", 30)
    assert "height: 300" in image and 'encoding: "mono8"' in image
    assert any(line.startswith("data: 90000 bytes: 000102030405") for line in image)
    assert any("the capture holds 4096 of the 90042 bytes" in line for line in image)


def test_services_are_decoded_with_the_embedded_definition_and_the_ok_byte(traced_capture):
    lua, capture = traced_capture
    out = _tshark(lua, capture, "-O", "minros", "-Y", "minros")
    assert _section(out, "TCPROS request 1: rospy_tutorials/AddTwoIntsRequest", 6)[4:] == [
        "a: 4", "b: 5"]
    response = _section(out, "TCPROS response 1: rospy_tutorials/AddTwoIntsResponse", 6)
    assert response[2] == "ok: 1 (a response follows)" and response[5] == "sum: 9"
    failed = _section(out, "TCPROS response 1: ok=0, the service failed", 5)
    assert failed[2] == "ok: 0 (an error text follows)"
    assert failed[4] == 'error: "service cannot process request: a must not be 0"'
    probe = _section(out, "TCPROS connection header (client), 70 bytes, 4 fields", 6)
    assert "probe=1" in probe and "md5sum=*" in probe


def test_the_fields_can_be_filtered_on(traced_capture):
    lua, capture = traced_capture
    rows = _tshark(lua, capture, "-Y", "minros.float64 == -2.25 && minros.msgtype",
                   "-T", "fields", "-e", "minros.msgtype").split()
    assert rows == ["geometry_msgs/Point"]
    topics = set(_tshark(lua, capture, "-Y", "minros.topic", "-T", "fields", "-e",
                         "minros.topic").split())
    assert {"/point", "/pose", "/joints", "/count", "/image", "/burst"} <= topics


def test_without_the_service_type_the_body_stays_bytes_and_says_why(traced_capture, tmp_path):
    _lua, capture = traced_capture
    bare = tmp_path / "bare.lua"
    done = subprocess.run([PYTHON, "-m", "minros", "trace", "dissector", "-o", str(bare)],
                          capture_output=True, text=True, timeout=60)
    assert done.returncode == 0, done.stderr
    out = _tshark(bare, capture, "-O", "minros", "-Y", "minros")
    assert "TCPROS request 1, 16 bytes (not decoded: service type rospy_tutorials/AddTwoInts " \
           "is not in this dissector" in out
    assert "y: -2.25" in out  # topics need nothing embedded


def test_a_real_capture_with_segmentation(tmp_path):
    """dumpcap on the loopback of a private network namespace (root only): frames split over
    segments and coalesced into one are reassembled and cut by the dissector."""
    _need_tshark()
    if os.geteuid() != 0:
        pytest.skip("a live capture needs root (for a network namespace and dumpcap)")
    need(shutil.which("unshare") is not None and shutil.which("dumpcap") is not None,
         "unshare and dumpcap are needed for a live capture")
    home = tmp_path / "ros_home"
    (home / "log").mkdir(parents=True)
    port = free_port()
    env = ros_env(port, home, {"MINROS_SHM": "0"})  # TCPROS on the wire, as above
    script = tmp_path / "scenario.py"
    script.write_text(SCENARIO)
    capture = tmp_path / "live.pcapng"
    # everything in one namespace, so the capture holds this test's traffic only
    run = f"""
set -e
ip link set lo up
dumpcap -q -i lo -f "tcp or udp port 9" -w {capture} & DUMPCAP=$!
while [ ! -s {capture} ]; do sleep 0.05; done
{PYTHON} -m minros core -p {port} > {tmp_path}/core.log 2>&1 & CORE=$!
{PYTHON} -c 'import sys, time, xmlrpc.client as x
for _ in range(200):
    try:
        x.ServerProxy("http://127.0.0.1:{port}/").getPid("/t"); sys.exit(0)
    except OSError: time.sleep(0.05)
sys.exit("no master")'
{PYTHON} {script}
kill -INT $CORE; wait $CORE || true
# dumpcap stops on SIGINT without reading what the kernel still holds for it, and a busy
# machine leaves it behind: a datagram after the traffic, and SIGINT once it is in the file
{PYTHON} -c 'import socket; socket.socket(socket.AF_INET, socket.SOCK_DGRAM).sendto(b"minros-capture-end", ("127.0.0.1", 9))'
i=0; until grep -q minros-capture-end {capture} || [ $i -ge 600 ]; do i=$((i+1)); sleep 0.05; done
kill -INT $DUMPCAP; wait $DUMPCAP || true
"""
    done = subprocess.run(["unshare", "--net", "sh", "-c", run], env=env, capture_output=True,
                          text=True, timeout=120)
    if done.returncode != 0 and "unshare failed" in done.stderr:
        pytest.fail(done.stderr) if IN_CI else pytest.skip(done.stderr.strip())
    assert done.returncode == 0 and "received" in done.stdout, done.stdout + done.stderr
    lua = tmp_path / "minros.lua"
    subprocess.run([PYTHON, "-m", "minros", "trace", "dissector", "-o", str(lua), "--type",
                    "rospy_tutorials/AddTwoInts"], check=True, capture_output=True, timeout=60)
    out = _tshark(lua, capture, "-O", "minros", "-Y", "minros")
    assert _section(out, "TCPROS message 1: geometry_msgs/Point, 24 bytes", 7)[4:] == [
        "x: 1.0", "y: -2.25", "z: 0.0"]
    image = _section(out, "TCPROS message 1: sensor_msgs/Image, 90042 bytes", 30)
    assert "height: 300" in image
    assert not any("the capture holds" in line for line in image)  # reassembled whole
    burst = [line for line in out.splitlines()
             if line.startswith("TCPROS message ") and "geometry_msgs/Point" in line]
    assert len(burst) == 201, done.stdout  # /point's one and /burst's 200, however TCP cut them
    assert "TCPROS message 200: geometry_msgs/Point, 24 bytes" in burst
    assert "sum: 9" in out
