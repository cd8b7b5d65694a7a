"""MINROSSHM between real minros processes: images through shared memory, nothing left behind
when either side is killed with SIGKILL, the fallback to TCPROS when the publisher's kernel
refuses the memory or its notifications are garbage (one log line, messages keep coming),
MINROS_SHM=0, the trace, and intra-process delivery."""

from __future__ import annotations

import os
import re
import shutil
import signal
import subprocess
import xmlrpc.client
from pathlib import Path

import pytest

from minros.transport import shm as shm_transport
from support import PYTHON, Proc, ros_env, wait_until

pytestmark = pytest.mark.skipif(not shm_transport.supported(), reason="no memfd on this system")

#: publishes 640x480 mono8 images at 50 Hz, pixel value = the message's number (argv: count,
#: 0 for endless); optionally breaks the protocol first (MINROS_TEST_GARBAGE=1), or fills
#: the pixels in memory from Publisher.loan() (MINROS_TEST_LOAN=1)
PUBLISHER = r'''
import os, resource, sys, time
if os.environ.get("MINROS_TEST_FSIZE"):
    # memfd's size counts against RLIMIT_FSIZE: the kernel refuses a 300 KB segment (EFBIG;
    # Python ignores SIGXFSZ)
    limit = int(os.environ["MINROS_TEST_FSIZE"])
    resource.setrlimit(resource.RLIMIT_FSIZE, (limit, limit))
import rospy
from sensor_msgs.msg import Image
if os.environ.get("MINROS_TEST_GARBAGE"):
    # a publisher speaking MINROSSHM wrongly: every slot record is garbage
    from minros.wire import shm
    shm.slot = lambda *args: b"JUNK" * 7
rospy.init_node("camera")
pub = rospy.Publisher("/image", Image, queue_size=5)
count = int(sys.argv[1])
print("advertised", flush=True)
n = 0
rate = rospy.Rate(50)
try:
    while not rospy.is_shutdown() and (count == 0 or n < count):
        if os.environ.get("MINROS_TEST_LOAN"):  # the pixels written into a loan
            data = pub.loan(640 * 480)
            data[:] = bytes([n % 256]) * (640 * 480)
        else:
            data = bytes([n % 256]) * (640 * 480)
        pub.publish(Image(height=480, width=640, encoding="mono8", step=640, data=data))
        n += 1
        rate.sleep()
except rospy.ROSInterruptException:  # stopped with Ctrl-C
    pass
'''

#: checks every image's pixels in its callback; prints its connection's transport
SUBSCRIBER = r'''
import sys, threading, xmlrpc.client
import rospy
from sensor_msgs.msg import Image
rospy.init_node("viewer")
seen = {"n": 0, "bad": 0}
def on_image(msg):
    data = msg.data
    if len(data) != 640 * 480 or data[0] != data[-1] or data[1000] != data[0]:
        seen["bad"] += 1
    seen["n"] += 1
    if seen["n"] % 5 == 0:
        uri = rospy.get_node_uri()
        info = xmlrpc.client.ServerProxy(uri).getBusInfo("/viewer")[2]
        kinds = sorted(c[3] for c in info if c[4] == "/image")
        print("got", seen["n"], "bad", seen["bad"], "type", type(data).__name__,
              "transport", ",".join(kinds), flush=True)
rospy.Subscriber("/image", Image, on_image, queue_size=2)
print("subscribed", flush=True)
rospy.spin()
'''


@pytest.fixture
def scripts(tmp_path: Path):
    pub, sub = tmp_path / "camera.py", tmp_path / "viewer.py"
    pub.write_text(PUBLISHER)
    sub.write_text(SUBSCRIBER)
    return pub, sub


def _start(script: Path, args, port: int, home: Path, extra=None) -> Proc:
    return Proc([PYTHON, str(script), *map(str, args)], ros_env(port, home, extra))


def memfds(pid: int) -> list:
    """The minros shared-memory segments process ``pid`` holds open or mapped."""
    found = []
    try:
        for fd in os.listdir(f"/proc/{pid}/fd"):
            try:
                target = os.readlink(f"/proc/{pid}/fd/{fd}")
            except OSError:
                continue
            if "memfd:minros-shm" in target:
                found.append(target)
        with open(f"/proc/{pid}/maps") as maps:
            found += [line.split(None, 5)[-1].strip() for line in maps if "memfd:minros-shm" in line]
    except FileNotFoundError:
        pass
    return found


def dev_shm() -> set:
    return {name for name in os.listdir("/dev/shm") if "minros" in name}


def _line(text: str, pattern: str) -> str:
    lines = [line for line in text.splitlines() if re.search(pattern, line)]
    assert lines, f"no line matching {pattern!r} in:\n{text}"
    return lines[-1]


@pytest.mark.smoke
def test_images_go_through_shared_memory_and_sigkill_leaves_nothing(scripts, minros_master,
                                                                   ros_home):
    pub_script, sub_script = scripts
    before = dev_shm()
    sub = _start(sub_script, [], minros_master, ros_home)
    pub = pub2 = None
    try:
        sub.read_until("subscribed", 20)
        pub = _start(pub_script, [0], minros_master, ros_home)
        out = sub.read_until("got 10 ", 30)
        line = _line(out, r"^got 10 ")
        assert "bad 0" in line and "type memoryview" in line and "transport MINROSSHM" in line
        assert memfds(pub.pid) and memfds(sub.pid)  # memfds, not files
        assert dev_shm() == before

        pub.popen.send_signal(signal.SIGKILL)  # the publisher dies mid-stream
        pub.popen.wait(10)
        wait_until(lambda: not memfds(sub.pid), 20, what="the subscriber unmapping the segment")
        assert sub.alive()

        pub2 = _start(pub_script, [0], minros_master, ros_home)  # the subscriber reconnects
        out = sub.read_until("got 20 ", 30)
        assert "bad 0" in _line(out, r"^got 20 ")
        wait_until(lambda: memfds(pub2.pid), 10, what="the new publisher's segment")
        sub.popen.send_signal(signal.SIGKILL)  # now the subscriber dies
        sub.popen.wait(10)
        wait_until(lambda: not memfds(pub2.pid), 20, what="the publisher closing the segment")
        assert pub2.alive()
        assert dev_shm() == before
    finally:
        for proc in (pub, pub2, sub):
            if proc is not None:
                proc.stop()


def _full_dev_shm(argv) -> list:
    """``argv`` in a mount namespace of its own whose /dev/shm is a full 4 KiB tmpfs."""
    script = ("mount -t tmpfs -o size=4k tmpfs /dev/shm && "
              "dd if=/dev/zero of=/dev/shm/fill bs=4k count=1 2>/dev/null && "
              "! (echo x > /dev/shm/more) 2>/dev/null && exec \"$@\"")
    return ["unshare", "--mount", "--propagation", "private", "sh", "-c", script, "sh", *argv]


@pytest.mark.skipif(os.geteuid() != 0 or not shutil.which("unshare"),
                    reason="needs root and unshare for a private /dev/shm")
def test_a_full_dev_shm_changes_nothing(scripts, minros_master, ros_home):
    """Docker's /dev/shm is 64 MB, often full: memfd memory is not in it."""
    pub_script, sub_script = scripts
    sub = Proc(_full_dev_shm([PYTHON, str(sub_script)]), ros_env(minros_master, ros_home))
    pub = None
    try:
        sub.read_until("subscribed", 20)
        pub = Proc(_full_dev_shm([PYTHON, str(pub_script), "0"]),
                   ros_env(minros_master, ros_home))
        line = _line(sub.read_until("got 10 ", 30), r"^got 10 ")
    finally:
        for proc in (pub, sub):
            if proc is not None:
                proc.stop()
    assert "bad 0 type memoryview transport MINROSSHM" in line, line


@pytest.mark.parametrize("shm_env, transport", [("1", "MINROSSHM"), ("0", "TCPROS")])
def test_a_loaned_image_reaches_a_subscriber_of_either_transport(scripts, minros_master,
                                                                 ros_home, shm_env, transport):
    """Publisher.loan(): the slot's memory for a shared-memory subscriber, plain memory for
    a TCPROS one; the pixels arrive whole either way."""
    pub_script, sub_script = scripts
    sub = _start(sub_script, [], minros_master, ros_home, {"MINROS_SHM": shm_env})
    pub = None
    try:
        sub.read_until("subscribed", 20)
        pub = _start(pub_script, [0], minros_master, ros_home, {"MINROS_TEST_LOAN": "1"})
        line = _line(sub.read_until("got 20 ", 30), r"^got 20 ")
    finally:
        for proc in (pub, sub):
            if proc is not None:
                proc.stop()
    assert "bad 0" in line and f"transport {transport}" in line, line


def test_minros_shm_0_keeps_a_subscriber_on_tcpros(scripts, minros_master, ros_home):
    pub_script, sub_script = scripts
    sub = _start(sub_script, [], minros_master, ros_home, {"MINROS_SHM": "0"})
    pub = None
    try:
        sub.read_until("subscribed", 20)
        pub = _start(pub_script, [0], minros_master, ros_home)
        line = _line(sub.read_until("got 5 ", 30), r"^got 5 ")
        assert "transport TCPROS" in line and "type bytes" in line
        assert not memfds(pub.pid)
    finally:
        for proc in (pub, sub):
            if proc is not None:
                proc.stop()


def test_memory_refused_by_the_kernel_falls_back_to_tcpros_with_one_line(scripts, minros_master,
                                                                         ros_home):
    """Not simulated: the publisher runs under RLIMIT_FSIZE, so ftruncate on its memfd fails
    (EFBIG, SIGXFSZ ignored as Python does); the subscriber goes on over TCPROS."""
    pub_script, sub_script = scripts
    sub = _start(sub_script, [], minros_master, ros_home)
    pub = None
    try:
        sub.read_until("subscribed", 20)
        pub = _start(pub_script, [0], minros_master, ros_home, {"MINROS_TEST_FSIZE": "100000"})
        out = sub.read_until("got 10 ", 30)
        assert "bad 0" in _line(out, r"^got 10 ") and "transport TCPROS" in _line(out, r"^got 10 ")
        pub_out = pub.stop()
        sub_out = out + sub.stop()  # read_until() consumed the lines up to "got 10"
    finally:
        for proc in (pub, sub):
            if proc is not None:
                proc.stop()
    said = [line for line in pub_out.splitlines() if "shared memory" in line]
    assert len(said) == 1 and "File too large" in said[0] and "TCPROS" in said[0], pub_out
    fell = [line for line in sub_out.splitlines() if "MINROSSHM" in line and "failed" in line]
    assert len(fell) == 1 and "File too large" in fell[0], sub_out
    assert "Traceback" not in pub_out + sub_out


def test_garbage_notifications_fall_back_to_tcpros_with_one_line(scripts, minros_master, ros_home):
    pub_script, sub_script = scripts
    sub = _start(sub_script, [], minros_master, ros_home)
    pub = None
    try:
        sub.read_until("subscribed", 20)
        pub = _start(pub_script, [0], minros_master, ros_home, {"MINROS_TEST_GARBAGE": "1"})
        out = sub.read_until("got 10 ", 30)
        assert "bad 0" in _line(out, r"^got 10 ") and "transport TCPROS" in _line(out, r"^got 10 ")
        sub_out = out + sub.stop()
    finally:
        for proc in (pub, sub):
            if proc is not None:
                proc.stop()
    fell = [line for line in sub_out.splitlines() if "MINROSSHM" in line]
    assert len(fell) == 1 and "unknown record b'JUNK'" in fell[0], sub_out
    assert "Traceback" not in sub_out


def test_the_trace_shows_the_shared_memory_connection(scripts, minros_master, ros_home, tmp_path):
    pub_script, sub_script = scripts
    trace = tmp_path / "run.jsonl"
    # a traced process keeps to TCPROS unless asked (minros trace --shm): asked here
    env = ros_env(minros_master, ros_home, {"MINROS_TRACE": str(trace), "MINROS_TRACE_SHM": "1"})
    sub = Proc([PYTHON, str(sub_script)], env)
    pub = None
    try:
        sub.read_until("subscribed", 20)
        pub = Proc([PYTHON, str(pub_script), "20"], env)
        sub.read_until("got 10 ", 30)
    finally:
        for proc in (pub, sub):
            if proc is not None:
                proc.stop()
    done = subprocess.run([PYTHON, "-m", "minros", "trace", "show", "--topic", "/image",
                           str(trace)], capture_output=True, text=True, timeout=60)
    assert done.returncode == 0, done.stderr
    text = done.stdout
    assert re.search(r'\[3\].*requestTopic\("/viewer", "/image", \[\["MINROSSHM", 1, "[-0-9a-f]+"\], '
                     r'\["TCPROS"\]\]\)', text), text
    assert re.search(r'\[4\].*<- 1, "ready on minros-shm\.\d+\.[0-9a-f]+:.*\["MINROSSHM", ', text)
    assert re.search(r"\[5\].*/viewer -> /camera\s+MINROSSHM: Unix socket connection @[0-9a-f]+ -> "
                     r"@minros-shm\.\d+\.[0-9a-f]+ \(shared memory\)", text), text
    assert re.search(r"\[5\].*/camera -> /viewer\s+shared-memory segment 1: 3 slots of 311296 "
                     r"bytes \(its memfd passed with this record\)", text), text
    assert re.search(r"\[6\].*/camera -> /viewer\s+message 1: 307\d\d\d bytes in slot 0 of segment 1 "
                     r"\(shared memory\), received [\d.]+ ms later", text), text
    assert "MINROSSHM is minros's shared memory" in text


INTRA = r'''
import threading, time, xmlrpc.client
import rospy
from sensor_msgs.msg import Image
rospy.init_node("camera")
got = []
all_in = threading.Event()
rospy.Subscriber("/image", Image, lambda m: (got.append(m), len(got) == 100 and all_in.set()))
pub = rospy.Publisher("/image", Image, queue_size=5, intraprocess=True)
deadline = time.monotonic() + 30
while pub.get_num_connections() < 2 and time.monotonic() < deadline:  # ours, and the viewer
    time.sleep(0.01)
sent = []
rate = rospy.Rate(50)
for n in range(100):
    sent.append(Image(height=480, width=640, encoding="mono8", step=640,
                      data=bytes([n % 256]) * (640 * 480)))
    pub.publish(sent[-1])
    rate.sleep()
all_in.wait(20)
info = xmlrpc.client.ServerProxy(rospy.get_node_uri()).getBusInfo("/x")[2]
print("RESULT same", len(got) == len(sent) and all(a is b for a, b in zip(got, sent)),
      "count", len(got), "transports", sorted(c[3] + c[2] for c in info if c[4] == "/image"),
      flush=True)
'''


def test_intraprocess_hands_over_the_object(scripts, tmp_path, minros_master, ros_home):
    """A subscriber of the publishing process gets the very objects published; a subscriber
    in another process at the same time gets them through shared memory."""
    _, sub_script = scripts
    script = tmp_path / "composed.py"
    script.write_text(INTRA)
    viewer = _start(sub_script, [], minros_master, ros_home)
    proc = None
    try:
        viewer.read_until("subscribed", 20)
        proc = Proc([PYTHON, str(script)], ros_env(minros_master, ros_home))
        out = proc.read_until("RESULT", 60)
        seen = _line(viewer.read_until("got 50 ", 30), "^got 50 ")
    finally:
        for each in (proc, viewer):
            if each is not None:
                each.stop()
    line = _line(out, "^RESULT")
    assert "same True count 100" in line, line
    assert "['INTRAPROCESSi', 'INTRAPROCESSo', 'MINROSSHMo']" in line, line
    assert "bad 0" in seen and "transport MINROSSHM" in seen


def test_bus_info_names_the_peer_process(scripts, minros_master, ros_home):
    pub_script, sub_script = scripts
    sub = _start(sub_script, [], minros_master, ros_home)
    pub = None
    try:
        sub.read_until("subscribed", 20)
        pub = _start(pub_script, [0], minros_master, ros_home)
        sub.read_until("got 5 ", 30)
        master = xmlrpc.client.ServerProxy(f"http://127.0.0.1:{minros_master}/")
        uri = master.lookupNode("/t", "/camera")[2]
        info = [c for c in xmlrpc.client.ServerProxy(uri).getBusInfo("/t")[2] if c[4] == "/image"]
        assert len(info) == 1 and info[0][3] == "MINROSSHM"
        assert f"to [pid {sub.pid}]" in info[0][6] and "3 slots of 311296 bytes" in info[0][6]
    finally:
        for proc in (pub, sub):
            if proc is not None:
                proc.stop()
