#!/usr/bin/env python3
"""Publish/subscribe benchmark: minros vs Debian's rospy vs roscpp vs raw Python sockets.

    .venv/bin/python benchmarks/pubsub.py [--rounds 3] [--seconds 2] [--only minros,rospy]

Each scenario runs a pair of processes of one implementation on one master (Debian's
rosmaster when installed, else minros's): the contenders are interleaved round by round and
the table shows the median of the rounds plus ratios, because this machine is shared and
noisy (see shared/spec/ros1-reference.md).

Scenarios
* ping-pong round trip of a 20-byte std_msgs/String (each side answers from its receive
  callback, subscriber tcp_nodelay), publisher queue_size=10 and queue_size=None; the CPU
  time the pinging process spends per round trip is shown too (steadier than wall time on a
  shared machine). Two raw-socket floors, both with a 4-byte length prefix and nothing else:
  "raw" has ROS's topology (each direction its own connection, as each topic is, and each
  side answering from a receive thread, as a subscriber callback does); "raw-1" is one
  bidirectional connection with blocking send/recv in the main thread, the absolute floor.
  "py-min" is "raw" plus the least any Python client must do per message: decode the
  String into an object and encode it again (no middleware, no checks, no queues);
* small-message flood: std_msgs/String "x"*20 published as fast as possible for N seconds,
  messages per second *received*;
* 640x480 and 1920x1080 bgr8 sensor_msgs/Image floods, frames per second received; the
  publisher has queue_size=10, so a loop publishing faster than the wire drops frames and its
  spinning competes for the CPUs with the thread that sends (on every implementation); the
  1920x1080 flood is also run with queue_size=None (publish() sends before it returns, as the
  raw floor's sendall does), which measures the receive path at wire speed; each flood also
  shows the CPU both processes spent per message received (publishing loop and sending
  thread included), steadier than the rate on a shared machine;
* idle node memory: RSS of a node that did nothing but init_node;
* service calls of std_srvs/SetBool, persistent and with a new connection (and master
  lookup) per call, median round trip;
* fan-out: one publisher flooding 8 subscriber processes (small messages, 640x480 images),
  messages per second delivered in all;
* a subscriber's CPU (% of one core) while it receives a 1920x1080 bgr8 topic at 30 Hz;
* shared memory (minros's MINROSSHM between two minros processes; every other minros row
  runs with MINROS_SHM=0, i.e. over TCPROS): the 1920x1080 and 3840x2160 bgr8 floods, a
  20 MB sensor_msgs/PointCloud2 flood, the small-message flood and round trip (small
  messages go inline on its Unix socket), the 30 Hz subscriber's CPU; the "raw" column of
  these rows is the raw TCP floor measured again in the same round, so minros/raw says how
  far shared memory goes past the socket;
* intra-process: one minros process publishing 1920x1080 images with intraprocess=True to
  its own subscriber (the object handed over, no serialization);
* bring-up: 100 nodes, each publishing 10 topics and subscribing to the next node's 10, started
  at once: seconds until every connection is made (minros and rospy);
* `rostopic hz` and `rostopic echo` (minros's and Debian's) on a 10 kHz std_msgs/String topic
  from the same publisher: % of one core the tool uses.

``--trace`` adds "minros+trace": minros with every process writing a wire trace of every frame
(MINROS_TRACE, MINROS_TRACE_FRAMES=all), the cost of ``minros trace``. ``--baseline PY|DIR``
adds "baseline": minros run by another interpreter (e.g. a venv of another checkout), or a
checkout's ``src/`` and ``stubs/`` run by the minros workers' interpreter (PYTHONPATH; its
bytecode cached outside the checkout, which is left as it is), so two versions are compared in
one interleaved run.

This same file is also the worker: ``--role ...`` runs one side of a scenario, in whichever
Python runs it (the venv's for minros and raw, /usr/bin/python3 for rospy), and prints one JSON
line. ``--minros-python`` picks another interpreter for minros and raw, e.g. a venv made from
/usr/bin/python3 so that minros and rospy run on the very same interpreter build.
"""

from __future__ import annotations

import argparse
import hashlib
import json
import os
import platform
import shutil
import socket
import statistics
import struct
import subprocess
import sys
import tempfile
import threading
import time

from _bytecode import byte_compile_minros  # benchmarks/ is the script's directory: on sys.path

HERE = os.path.dirname(os.path.abspath(__file__))
REPO = os.path.dirname(HERE)
VENV_PYTHON = os.path.join(REPO, ".venv", "bin", "python")
REFERENCE_PYTHON = "/usr/bin/python3"
KINDS = {"small": None, "vga": (480, 640), "hd": (1080, 1920), "4k": (2160, 3840)}
#: the PointCloud2 flood: 20 MB of points (16 bytes each: x, y, z, intensity as float32)
CLOUD_POINTS = 20_000_000 // 16

# --------------------------------------------------------------------------------- workers


def _make(kind: str):
    if kind == "small":
        from std_msgs.msg import String

        return String, String("x" * 20)
    if kind == "cloud":
        from sensor_msgs.msg import PointCloud2, PointField

        cloud = PointCloud2()
        cloud.header.frame_id = "lidar"
        cloud.height, cloud.width = 1, CLOUD_POINTS
        cloud.fields = [PointField(name, 4 * i, PointField.FLOAT32, 1)
                        for i, name in enumerate(("x", "y", "z", "intensity"))]
        cloud.point_step, cloud.row_step = 16, 16 * CLOUD_POINTS
        cloud.data = bytes(16 * CLOUD_POINTS)
        cloud.is_dense = True
        return PointCloud2, cloud
    from sensor_msgs.msg import Image

    height, width = KINDS[kind]
    msg = Image()
    msg.height, msg.width, msg.encoding, msg.step = height, width, "bgr8", width * 3
    msg.header.frame_id = "camera"
    msg.data = bytes(height * width * 3)
    return Image, msg


def _queue(text: str):
    return None if text == "none" else int(text)


def _wait_connections(pub, n: int = 1, timeout: float = 20.0) -> None:
    deadline = time.monotonic() + timeout
    while pub.get_num_connections() < n:
        if time.monotonic() > deadline:
            raise SystemExit("no subscriber connected")
        time.sleep(0.005)


def role_echo(args) -> None:
    import warnings

    import rospy
    from std_msgs.msg import String

    warnings.simplefilter("ignore", SyntaxWarning)
    rospy.init_node("bench_echo", anonymous=True)
    pub = rospy.Publisher("/bench_pong", String, queue_size=_queue(args.queue), tcp_nodelay=True)
    rospy.Subscriber("/bench_ping", String, pub.publish, tcp_nodelay=True)
    print(json.dumps({"ready": True}), flush=True)
    rospy.spin()


class _RoundTrips:
    """The pinging side's clock, the same code for every contender: ``on_pong`` records one
    round trip and sends the next ping (from the receive thread, as a callback does)."""

    WARMUP = 200

    def __init__(self, count: int, send) -> None:
        self.total = count + self.WARMUP
        self.send = send
        self.times: list = []
        self.n = 0
        self.t = 0.0
        self.cpu = 0.0
        self.done = threading.Event()

    def start(self) -> None:
        self.cpu = time.process_time()
        self.t = time.perf_counter()
        self.send()

    def on_pong(self, _msg=None) -> bool:
        now = time.perf_counter()
        self.n += 1
        if self.n > self.WARMUP:
            self.times.append(now - self.t)
        if self.n >= self.total:
            self.done.set()
            return True
        self.t = time.perf_counter()
        self.send()
        return False

    def report(self) -> None:
        if not self.done.wait(60):
            raise SystemExit(f"ping-pong stalled after {self.n} round trips")
        cpu = time.process_time() - self.cpu
        print(json.dumps({"median_us": statistics.median(self.times) * 1e6,
                          "mean_us": statistics.mean(self.times) * 1e6,
                          "cpu_us": cpu / self.total * 1e6}), flush=True)


def role_ping(args) -> None:
    import warnings

    import rospy
    from std_msgs.msg import String

    warnings.simplefilter("ignore", SyntaxWarning)
    rospy.init_node("bench_ping", anonymous=True)
    pub = rospy.Publisher("/bench_ping", String, queue_size=_queue(args.queue), tcp_nodelay=True)
    msg = String("x" * 16)  # 20 bytes on the wire
    clock = _RoundTrips(args.count, lambda: pub.publish(msg))
    rospy.Subscriber("/bench_pong", String, clock.on_pong, tcp_nodelay=True)
    _wait_connections(pub)
    time.sleep(0.5)  # the echo's publisher needs our subscription too
    clock.start()
    clock.report()
    rospy.signal_shutdown("done")


def role_flood_pub(args) -> None:
    import warnings

    import rospy

    warnings.simplefilter("ignore", SyntaxWarning)
    cls, msg = _make(args.kind)
    rospy.init_node("bench_flood_pub", anonymous=True)
    pub = rospy.Publisher("/bench_flood", cls, queue_size=_queue(args.queue))
    _wait_connections(pub, args.subs)
    time.sleep(0.3)
    sent = 0
    cpu = time.process_time()
    end = time.monotonic() + args.seconds
    while time.monotonic() < end:
        for _ in range(10):
            pub.publish(msg)
        sent += 10
    time.sleep(0.5)  # what is queued still goes out: the writer's CPU counts too
    print(json.dumps({"sent": sent, "pub_cpu_s": time.process_time() - cpu}), flush=True)
    time.sleep(0.5)
    rospy.signal_shutdown("done")


def role_flood_sub(args) -> None:
    import rospy

    cls, _ = _make(args.kind)
    stamps: list = []

    cpu = [0.0]

    def on_msg(_msg) -> None:
        if not stamps:
            cpu[0] = time.process_time()
        stamps.append(time.perf_counter())

    rospy.init_node("bench_flood_sub", anonymous=True)
    rospy.Subscriber("/bench_flood", cls, on_msg, queue_size=None, buff_size=1 << 24)
    print(json.dumps({"ready": True}), flush=True)
    # report once the flow stopped for a while
    last = -1
    while True:
        time.sleep(0.5)
        if stamps and len(stamps) == last:
            break
        last = len(stamps)
    n = len(stamps)
    rate = (n - 1) / (stamps[-1] - stamps[0]) if n > 1 else 0.0
    print(json.dumps({"received": n, "rate": rate, "sub_cpu_s": time.process_time() - cpu[0]}),
          flush=True)
    rospy.signal_shutdown("done")


def role_intra_flood(args) -> None:
    """One process publishing to its own subscriber with intraprocess=True: messages per
    second the callback receives (the object itself, handed over)."""
    import warnings

    import rospy

    warnings.simplefilter("ignore", SyntaxWarning)
    cls, msg = _make(args.kind)
    stamps: list = []
    rospy.init_node("bench_intra", anonymous=True)
    rospy.Subscriber("/bench_intra", cls, lambda _m: stamps.append(time.perf_counter()),
                     queue_size=None)
    pub = rospy.Publisher("/bench_intra", cls, queue_size=_queue(args.queue), intraprocess=True)
    _wait_connections(pub)
    time.sleep(0.3)
    end = time.monotonic() + args.seconds
    while time.monotonic() < end:
        for _ in range(10):
            pub.publish(msg)
    time.sleep(0.5)
    n = len(stamps)
    rate = (n - 1) / (stamps[-1] - stamps[0]) if n > 1 else 0.0
    print(json.dumps({"received": n, "rate": rate}), flush=True)
    rospy.signal_shutdown("done")


# services, fan-out, a subscriber's CPU, many nodes coming up

def _median_report(times: list, **extra) -> None:
    print(json.dumps({"median_us": statistics.median(times) * 1e6, **extra}), flush=True)


def role_srv_server(args) -> None:
    import rospy
    from std_srvs.srv import SetBool, SetBoolResponse

    rospy.init_node("bench_srv", anonymous=True)
    rospy.Service("/bench_srv", SetBool, lambda req: SetBoolResponse(req.data, "ok"))
    print(json.dumps({"ready": True}), flush=True)
    rospy.spin()


def role_srv_client(args) -> None:
    """Calls of std_srvs/SetBool, each timed; persistent or a new connection (and master
    lookup) per call, as rospy.ServiceProxy does either way."""
    import rospy
    from std_srvs.srv import SetBool

    rospy.wait_for_service("/bench_srv", timeout=20)
    proxy = rospy.ServiceProxy("/bench_srv", SetBool, persistent=args.persistent)
    times = []
    for i in range(args.count + 50):
        if i == 50:
            cpu = time.process_time()
        t = time.perf_counter()
        proxy(True)
        if i >= 50:
            times.append(time.perf_counter() - t)
    _median_report(times, cpu_us=(time.process_time() - cpu) / args.count * 1e6)


def role_rate_pub(args) -> None:
    """Publishes at ``--hz`` for ``--seconds``, paced by the clock (not a flood)."""
    import warnings

    import rospy

    warnings.simplefilter("ignore", SyntaxWarning)
    cls, msg = _make(args.kind)
    rospy.init_node("bench_rate_pub", anonymous=True)
    pub = rospy.Publisher("/bench_rate", cls, queue_size=10)
    _wait_connections(pub, args.subs)
    time.sleep(0.5)
    period = 1.0 / args.hz
    print(json.dumps({"started": True}), flush=True)
    start = time.perf_counter()
    n = 0
    while True:
        now = time.perf_counter()
        if now - start >= args.seconds:
            break
        target = start + n * period
        if now < target:
            time.sleep(min(target - now, 0.001) if target - now > 0.0015 else 0)
            continue
        pub.publish(msg)
        n += 1
    print(json.dumps({"sent": n}), flush=True)
    time.sleep(1.0)
    rospy.signal_shutdown("done")


def role_cpu_sub(args) -> None:
    """Counts messages on /bench_rate and reports the CPU this process spent per second of flow."""
    import rospy

    cls, _ = _make(args.kind)
    seen = {"n": 0, "cpu0": 0.0, "t0": 0.0, "cpu1": 0.0, "t1": 0.0}

    def on_msg(_msg) -> None:
        if seen["n"] == 0:
            seen["cpu0"], seen["t0"] = time.process_time(), time.perf_counter()
        seen["n"] += 1
        seen["cpu1"], seen["t1"] = time.process_time(), time.perf_counter()

    rospy.init_node("bench_cpu_sub", anonymous=True)
    rospy.Subscriber("/bench_rate", cls, on_msg, queue_size=10, buff_size=1 << 24)
    print(json.dumps({"ready": True}), flush=True)
    last = -1
    while True:
        time.sleep(0.5)
        if seen["n"] and seen["n"] == last:
            break
        last = seen["n"]
    span = seen["t1"] - seen["t0"]
    print(json.dumps({"received": seen["n"],
                      "cpu_percent": 100.0 * (seen["cpu1"] - seen["cpu0"]) / span if span else None}),
          flush=True)
    rospy.signal_shutdown("done")


#: seconds a ring node waits for its connections before it reports the ones missing
RING_TIMEOUT = 60.0


def role_ring_node(args) -> None:
    """Node ``index`` of a ring: publishes ``--topics`` topics and subscribes to those of the
    next node; says when every one of its connections is made, then waits to be stopped."""
    import warnings

    import rospy
    from std_msgs.msg import Empty

    warnings.simplefilter("ignore", SyntaxWarning)
    rospy.init_node(f"ring{args.index}")
    nxt = (args.index + 1) % args.nodes
    pubs = [rospy.Publisher(f"/ring{args.index}/t{k}", Empty, queue_size=1) for k in range(args.topics)]
    subs = [rospy.Subscriber(f"/ring{nxt}/t{k}", Empty) for k in range(args.topics)]
    deadline = time.monotonic() + RING_TIMEOUT
    while not all(p.get_num_connections() for p in pubs) or not all(s.get_num_connections() for s in subs):
        if rospy.is_shutdown():
            return
        if time.monotonic() > deadline:  # a connection the client library never made
            missing = sum(1 for sub in subs if not sub.get_num_connections())
            print(json.dumps({"missing": missing}), flush=True)
            break
        time.sleep(0.02)
    else:
        print(json.dumps({"connected": time.time()}), flush=True)
    sys.stdin.read()  # until the driver closes our stdin
    rospy.signal_shutdown("done")


# raw sockets: the same exchanges with a 4-byte length prefix and nothing else

def _recv_exact(sock, view) -> None:
    got = 0
    while got < len(view):
        n = sock.recv_into(view[got:])
        if not n:
            raise ConnectionError("peer closed")
        got += n


def _raw_listen(port: int, backlog: int) -> socket.socket:
    """The raw workers' listening socket; the driver starts the other side on the ready line."""
    server = socket.socket()
    server.setsockopt(socket.SOL_SOCKET, socket.SO_REUSEADDR, 1)
    server.bind(("127.0.0.1", port))
    server.listen(backlog)
    print(json.dumps({"ready": True}), flush=True)
    return server


def _raw_answer_loop(incoming, outgoing, on_frame) -> None:
    """A subscriber's receive thread reduced to sockets: read length-prefixed frames from
    ``incoming`` and hand each to ``on_frame`` (which may send on ``outgoing``)."""
    head = bytearray(4)
    body = bytearray(1 << 16)
    try:
        while True:
            _recv_exact(incoming, memoryview(head))
            (size,) = struct.unpack("<I", head)
            _recv_exact(incoming, memoryview(body)[:size])
            if on_frame(bytes(head) + bytes(body[:size])):
                return
    except (ConnectionError, OSError):
        pass


def role_raw_echo(args) -> None:
    server = _raw_listen(args.port, 1)
    conn, _ = server.accept()
    conn.setsockopt(socket.IPPROTO_TCP, socket.TCP_NODELAY, 1)
    _raw_answer_loop(conn, conn, conn.sendall)


def role_raw_ping(args) -> None:
    sock = socket.create_connection(("127.0.0.1", args.port))
    sock.setsockopt(socket.IPPROTO_TCP, socket.TCP_NODELAY, 1)
    payload = struct.pack("<I", 20) + struct.pack("<I", 16) + b"x" * 16
    reply = bytearray(len(payload))
    view = memoryview(reply)
    times = []
    cpu = time.process_time()
    for i in range(args.count + 200):
        t = time.perf_counter()
        sock.sendall(payload)
        _recv_exact(sock, view)
        if i >= 200:
            times.append(time.perf_counter() - t)
    cpu = time.process_time() - cpu
    print(json.dumps({"median_us": statistics.median(times) * 1e6,
                      "mean_us": statistics.mean(times) * 1e6,
                      "cpu_us": cpu / (args.count + 200) * 1e6}), flush=True)


class _MinimalString:
    """std_msgs/String with nothing but what any Python client must do per message."""

    __slots__ = ("data",)

    def __init__(self, data: str = "") -> None:
        self.data = data


_U32 = struct.Struct("<I")
_U32_PAIR = struct.Struct("<II")


def _decode_string(frame: bytes) -> _MinimalString:
    (size,) = _U32.unpack_from(frame, 4)
    return _MinimalString(frame[8:8 + size].decode())


def _encode_string(msg: _MinimalString) -> bytes:
    raw = msg.data.encode()
    return _U32_PAIR.pack(len(raw) + 4, len(raw)) + raw


def role_raw_pubsub_echo(args) -> None:
    """The echo of the ping-pong with ROS's topology and no middleware: the ping arrives on
    one connection (its "topic"), a receive thread answers on a second one."""
    server = _raw_listen(args.port, 2)
    incoming, _ = server.accept()
    outgoing, _ = server.accept()
    for sock in (incoming, outgoing):
        sock.setsockopt(socket.IPPROTO_TCP, socket.TCP_NODELAY, 1)
    answer = outgoing.sendall
    if args.messages:  # py-min: decode the String and encode it again, as any client must
        def answer(frame: bytes) -> None:
            outgoing.sendall(_encode_string(_decode_string(frame)))
    thread = threading.Thread(target=_raw_answer_loop, args=(incoming, outgoing, answer))
    thread.start()
    thread.join()


def role_raw_pubsub_ping(args) -> None:
    outgoing = socket.create_connection(("127.0.0.1", args.port))
    time.sleep(0.2)  # accepted first: the echo tells the two apart by order
    incoming = socket.create_connection(("127.0.0.1", args.port))
    for sock in (incoming, outgoing):
        sock.setsockopt(socket.IPPROTO_TCP, socket.TCP_NODELAY, 1)
    payload = struct.pack("<I", 20) + struct.pack("<I", 16) + b"x" * 16
    if args.messages:  # py-min: messages in and out, as in role_ping
        msg = _MinimalString("x" * 16)
        clock = _RoundTrips(args.count, lambda: outgoing.sendall(_encode_string(msg)))

        def on_frame(frame: bytes) -> bool:
            return clock.on_pong(_decode_string(frame))
    else:
        clock = _RoundTrips(args.count, lambda: outgoing.sendall(payload))
        on_frame = clock.on_pong
    threading.Thread(target=_raw_answer_loop, args=(incoming, outgoing, on_frame),
                     daemon=True).start()
    clock.start()
    clock.report()


def _frame_size(kind: str) -> int:
    if kind == "cloud":
        return 16 * CLOUD_POINTS
    height, width = KINDS[kind]
    return height * width * 3


def role_raw_flood_sub(args) -> None:
    server = _raw_listen(args.port, 1)
    conn, _ = server.accept()
    head = bytearray(4)
    body = bytearray(32 << 20)
    stamps = []
    cpu = 0.0
    try:
        while True:
            _recv_exact(conn, memoryview(head))
            (size,) = struct.unpack("<I", head)
            _recv_exact(conn, memoryview(body)[:size])
            if not stamps:
                cpu = time.process_time()
            stamps.append(time.perf_counter())
    except (ConnectionError, OSError):
        pass
    n = len(stamps)
    print(json.dumps({"received": n, "rate": (n - 1) / (stamps[-1] - stamps[0]) if n > 1 else 0.0,
                      "sub_cpu_s": time.process_time() - cpu}), flush=True)


def role_raw_flood_pub(args) -> None:
    sock = socket.create_connection(("127.0.0.1", args.port))
    if args.kind == "small":
        frame = struct.pack("<I", 24) + struct.pack("<I", 20) + b"x" * 20
    else:
        size = _frame_size(args.kind)
        frame = struct.pack("<I", size) + bytes(size)
    sent = 0
    cpu = time.process_time()
    end = time.monotonic() + args.seconds
    while time.monotonic() < end:
        for _ in range(10):
            sock.sendall(frame)
        sent += 10
    sock.close()
    print(json.dumps({"sent": sent, "pub_cpu_s": time.process_time() - cpu}), flush=True)


ROLES = {
    "echo": role_echo, "ping": role_ping, "flood-pub": role_flood_pub, "flood-sub": role_flood_sub,
    "raw-echo": role_raw_echo, "raw-ping": role_raw_ping, "raw-flood-pub": role_raw_flood_pub,
    "raw-flood-sub": role_raw_flood_sub, "raw-pubsub-echo": role_raw_pubsub_echo,
    "raw-pubsub-ping": role_raw_pubsub_ping, "srv-server": role_srv_server,
    "srv-client": role_srv_client, "rate-pub": role_rate_pub, "cpu-sub": role_cpu_sub,
    "ring-node": role_ring_node, "intra-flood": role_intra_flood,
}

# --------------------------------------------------------------------------------- roscpp

ROSCPP_SOURCE = r'''
#include <ros/ros.h>
#define CLOUD_POINTS 1250000
#include <std_msgs/String.h>
#include <sensor_msgs/Image.h>
#include <sensor_msgs/PointCloud2.h>
#include <std_srvs/SetBool.h>
#include <ctime>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>
#include <algorithm>

typedef std::chrono::steady_clock Clock;
static ros::Publisher pub;
static std::vector<double> times;
static Clock::time_point t0;
static int n = 0, total = 0;
static std::vector<Clock::time_point> stamps;
static std_msgs::String pingMsg;

static void onPing(const std_msgs::String::ConstPtr& m) { pub.publish(*m); }
static void onPong(const std_msgs::String::ConstPtr&) {
  Clock::time_point now = Clock::now();
  if (++n > 200) times.push_back(std::chrono::duration<double, std::micro>(now - t0).count());
  if (n >= total) { ros::shutdown(); return; }
  t0 = Clock::now();
  pub.publish(pingMsg);
}
template <class M> static void onFlood(const typename M::ConstPtr&) { stamps.push_back(Clock::now()); }
static bool onSetBool(std_srvs::SetBool::Request& req, std_srvs::SetBool::Response& res) {
  res.success = req.data; res.message = "ok"; return true;
}
static double cpuSeconds() { return (double)std::clock() / CLOCKS_PER_SEC; }
static int heightOf(const std::string& kind) { return kind == "vga" ? 480 : kind == "4k" ? 2160 : 1080; }
static int widthOf(const std::string& kind) { return kind == "vga" ? 640 : kind == "4k" ? 3840 : 1920; }
static double cpu0 = 0, cpu1 = 0;
static Clock::time_point first, last;
static long received = 0;
static void onImage(const sensor_msgs::Image::ConstPtr&) {
  if (received++ == 0) { cpu0 = cpuSeconds(); first = Clock::now(); }
  cpu1 = cpuSeconds(); last = Clock::now();
}

int main(int argc, char** argv) {
  ros::init(argc, argv, "bench_cpp", ros::init_options::AnonymousName | ros::init_options::NoSigintHandler);
  ros::NodeHandle nh;
  std::string role = argv[1], kind = argv[2];
  int queue = atoi(argv[3]);
  double seconds = atof(argv[4]);
  int count = atoi(argv[5]);
  ros::TransportHints hints = ros::TransportHints().tcpNoDelay();
  if (role == "echo") {
    pub = nh.advertise<std_msgs::String>("/bench_pong", queue);
    ros::Subscriber s = nh.subscribe("/bench_ping", 100, onPing, hints);
    printf("{\"ready\": true}\n"); fflush(stdout);
    ros::spin();
  } else if (role == "ping") {
    pub = nh.advertise<std_msgs::String>("/bench_ping", queue);
    ros::Subscriber s = nh.subscribe("/bench_pong", 100, onPong, hints);
    pingMsg.data = std::string(16, 'x');
    total = count + 200;
    while (pub.getNumSubscribers() == 0) ros::Duration(0.005).sleep();
    ros::AsyncSpinner spinner(1); spinner.start();
    ros::Duration(0.5).sleep();
    t0 = Clock::now();
    pub.publish(pingMsg);
    ros::waitForShutdown();
    std::sort(times.begin(), times.end());
    double sum = 0; for (double t : times) sum += t;
    printf("{\"median_us\": %f, \"mean_us\": %f}\n", times[times.size() / 2], sum / times.size());
  } else if (role == "flood-sub") {
    ros::Subscriber s;
    if (kind == "small") s = nh.subscribe<std_msgs::String>("/bench_flood", 100000, onFlood<std_msgs::String>);
    else if (kind == "cloud") s = nh.subscribe<sensor_msgs::PointCloud2>("/bench_flood", 100, onFlood<sensor_msgs::PointCloud2>);
    else s = nh.subscribe<sensor_msgs::Image>("/bench_flood", 100, onFlood<sensor_msgs::Image>);
    printf("{\"ready\": true}\n"); fflush(stdout);
    size_t last = (size_t)-1;
    ros::AsyncSpinner spinner(1); spinner.start();
    while (true) {
      ros::WallDuration(0.5).sleep();
      if (!stamps.empty() && stamps.size() == last) break;
      last = stamps.size();
    }
    size_t k = stamps.size();
    double span = k > 1 ? std::chrono::duration<double>(stamps.back() - stamps.front()).count() : 0;
    printf("{\"received\": %zu, \"rate\": %f}\n", k, span > 0 ? (k - 1) / span : 0.0);
  } else if (role == "srv-server") {
    ros::ServiceServer srv = nh.advertiseService("/bench_srv", onSetBool);
    printf("{\"ready\": true}\n"); fflush(stdout);
    ros::spin();
  } else if (role == "srv-client") {
    ros::service::waitForService("/bench_srv", 20000);
    ros::ServiceClient client = nh.serviceClient<std_srvs::SetBool>("/bench_srv", kind == "persistent");
    std_srvs::SetBool call; call.request.data = true;
    double cpuStart = 0;
    for (int i = 0; i < count + 50; ++i) {
      if (i == 50) cpuStart = cpuSeconds();
      Clock::time_point t = Clock::now();
      if (!client.call(call)) { printf("{\"error\": \"call failed\"}\n"); return 1; }
      if (i >= 50) times.push_back(std::chrono::duration<double, std::micro>(Clock::now() - t).count());
    }
    double cpuPerCall = (cpuSeconds() - cpuStart) / count * 1e6;
    std::sort(times.begin(), times.end());
    printf("{\"median_us\": %f, \"cpu_us\": %f}\n", times[times.size() / 2], cpuPerCall);
  } else if (role == "cpu-sub") {
    ros::Subscriber s = nh.subscribe<sensor_msgs::Image>("/bench_rate", 10, onImage);
    printf("{\"ready\": true}\n"); fflush(stdout);
    ros::AsyncSpinner spinner(1); spinner.start();
    long seen = -1;
    while (true) {
      ros::WallDuration(0.5).sleep();
      if (received && received == seen) break;
      seen = received;
    }
    double span = std::chrono::duration<double>(last - first).count();
    printf("{\"received\": %ld, \"cpu_percent\": %f}\n", received, span > 0 ? 100.0 * (cpu1 - cpu0) / span : 0.0);
  } else if (role == "rate-pub") {
    sensor_msgs::Image img; int h = heightOf(kind), w = widthOf(kind);
    img.height = h; img.width = w; img.encoding = "bgr8"; img.step = w * 3; img.data.assign(h * w * 3, 0);
    pub = nh.advertise<sensor_msgs::Image>("/bench_rate", queue);
    while (pub.getNumSubscribers() == 0) ros::Duration(0.005).sleep();
    ros::Duration(0.5).sleep();
    printf("{\"started\": true}\n"); fflush(stdout);
    ros::WallRate rate(count);
    Clock::time_point end = Clock::now() + std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(seconds));
    long sent = 0;
    while (Clock::now() < end) { pub.publish(img); ++sent; rate.sleep(); }
    printf("{\"sent\": %ld}\n", sent); fflush(stdout);
    ros::WallDuration(1.0).sleep();
  } else {  // flood-pub
    std_msgs::String small; small.data = std::string(20, 'x');
    sensor_msgs::Image img;
    sensor_msgs::PointCloud2 cloud;
    if (kind == "cloud") {
      const char* names[4] = {"x", "y", "z", "intensity"};
      for (int i = 0; i < 4; ++i) {
        sensor_msgs::PointField f; f.name = names[i]; f.offset = 4 * i; f.datatype = f.FLOAT32; f.count = 1;
        cloud.fields.push_back(f);
      }
      cloud.height = 1; cloud.width = CLOUD_POINTS; cloud.point_step = 16; cloud.row_step = 16 * CLOUD_POINTS;
      cloud.data.assign(16 * (size_t)CLOUD_POINTS, 0); cloud.is_dense = true;
    } else if (kind != "small") {
      int h = heightOf(kind), w = widthOf(kind);
      img.height = h; img.width = w; img.encoding = "bgr8"; img.step = w * 3; img.data.assign(h * w * 3, 0);
    }
    if (kind == "small") pub = nh.advertise<std_msgs::String>("/bench_flood", queue);
    else if (kind == "cloud") pub = nh.advertise<sensor_msgs::PointCloud2>("/bench_flood", queue);
    else pub = nh.advertise<sensor_msgs::Image>("/bench_flood", queue);
    while ((int)pub.getNumSubscribers() < std::max(count, 1)) ros::Duration(0.005).sleep();
    ros::Duration(0.3).sleep();
    long sent = 0;
    Clock::time_point end = Clock::now() + std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(seconds));
    while (Clock::now() < end) {
      for (int i = 0; i < 10; ++i) {
        if (kind == "small") pub.publish(small); else if (kind == "cloud") pub.publish(cloud); else pub.publish(img);
      }
      sent += 10;
      ros::spinOnce();
    }
    printf("{\"sent\": %ld}\n", sent); fflush(stdout);
    ros::WallDuration(1.0).sleep();
  }
  return 0;
}
'''


def build_roscpp(cache: str):
    """Compile the C++ worker (once); None when g++/roscpp are unavailable."""
    digest = hashlib.sha1(ROSCPP_SOURCE.encode()).hexdigest()[:12]
    binary = os.path.join(cache, f"bench_roscpp_{digest}")
    if os.path.exists(binary):
        return binary
    if not shutil.which("g++") or not shutil.which("pkg-config"):
        return None
    flags = subprocess.run(["pkg-config", "--cflags", "--libs", "roscpp", "std_msgs", "sensor_msgs",
                            "std_srvs"],
                           capture_output=True, text=True)
    if flags.returncode != 0:
        return None
    os.makedirs(cache, exist_ok=True)
    source = os.path.join(cache, "bench_roscpp.cpp")
    with open(source, "w") as f:
        f.write(ROSCPP_SOURCE)
    result = subprocess.run(["g++", "-O2", "-o", binary, source, *flags.stdout.split()],
                            capture_output=True, text=True)
    if result.returncode != 0:
        print("roscpp build failed:\n" + result.stderr[-2000:], file=sys.stderr)
        return None
    return binary


# --------------------------------------------------------------------------------- driver


def _cpu_seconds(pid: int) -> float:
    """user + system CPU seconds a running process has used (from /proc)."""
    with open(f"/proc/{pid}/stat") as f:
        fields = f.read().rpartition(")")[2].split()
    return (int(fields[11]) + int(fields[12])) / os.sysconf("SC_CLK_TCK")


def _pinned(command: tuple, cpu: int) -> tuple:
    """``command`` run on one CPU (taskset, so that roscpp's binary is pinned the same way)."""
    return (["taskset", "-c", str(cpu), *command[0]], command[1])


def _free_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


class Runner:
    def __init__(self, args) -> None:
        self.args = args
        self.cpu: dict = {}  # (queue, contender) -> CPU µs per round trip of the ping process
        self.shm = False  # minros workers may use shared memory (else MINROS_SHM=0: TCPROS)
        self.home = tempfile.mkdtemp(prefix="minros-bench-")
        self.port = _free_port()
        self.reference = os.path.exists(REFERENCE_PYTHON) and subprocess.run(
            [REFERENCE_PYTHON, "-c", "import rospy"], env=self.env(True), capture_output=True).returncode == 0
        self.roscpp = build_roscpp(os.path.join(tempfile.gettempdir(), "minros-bench-roscpp")) \
            if self.reference else None
        if self.reference:
            master = ["/usr/bin/rosmaster", "--core", "-p", str(self.port)]
            self.master = subprocess.Popen(master, env=self.env(True), stdout=subprocess.DEVNULL,
                                           stderr=subprocess.DEVNULL)
        else:
            self.master = subprocess.Popen([VENV_PYTHON, "-m", "minros.master", "-p", str(self.port)],
                                           env=self.env(False), stdout=subprocess.DEVNULL,
                                           stderr=subprocess.DEVNULL)
        time.sleep(1.5)

    def env(self, reference: bool) -> dict:
        env = {k: v for k, v in os.environ.items() if not k.startswith("ROS_") and k != "PYTHONPATH"}
        env.update(ROS_MASTER_URI=f"http://localhost:{self.port}", ROS_HOSTNAME="localhost",
                   ROS_HOME=self.home, ROS_LOG_DIR=os.path.join(self.home, "log"))
        if reference:
            env.pop("VIRTUAL_ENV", None)
            env["PATH"] = "/usr/bin:/bin"
        return env

    def contenders(self) -> list:
        names = ["minros"] + (["minros+trace"] if self.args.trace else []) + \
                (["baseline"] if self.args.baseline else []) + \
                (["rospy"] if self.reference else []) + \
                (["roscpp"] if self.roscpp else []) + ["py-min", "raw", "raw-1"]
        if self.args.only:
            names = [n for n in names if n in self.args.only.split(",")]
        return names

    def command(self, who: str, role: str, extra: list) -> tuple:
        if who == "roscpp":
            return [self.roscpp, *extra], self.env(True)
        baseline_dir = os.path.isdir(self.args.baseline) if self.args.baseline else False
        python = {"rospy": REFERENCE_PYTHON,
                  "baseline": self.args.minros_python if baseline_dir else self.args.baseline}.get(
            who, self.args.minros_python)
        env = self.env(who == "rospy")
        if who != "rospy":
            env["MINROS_SHM"] = "1" if self.shm else "0"
        if who == "baseline" and baseline_dir:
            env.update(baseline_env(self.args.baseline))
        if who == "minros+trace":
            # both processes append to one fresh trace, every frame of it (and keep to the
            # transport of the row: a traced process takes shared memory only when asked)
            path = os.path.join(self.home, "bench-trace.jsonl")
            if os.path.exists(path):
                os.remove(path)
            env.update(MINROS_TRACE=path, MINROS_TRACE_FRAMES="all",
                       MINROS_TRACE_SHM="1" if self.shm else "0")
        return [python, os.path.abspath(__file__), "--role", role, *extra], env

    def pair(self, who: str, first: tuple, second: tuple, timeout: float = 90,
             first_measures: bool = False) -> dict:
        """Start ``first`` (waits for its ready line), run ``second``; the result is the JSON
        printed by ``second``, plus ``first``'s last line when ``first_measures``."""
        p1 = subprocess.Popen(first[0], env=first[1], stdout=subprocess.PIPE, stderr=subprocess.DEVNULL,
                              text=True)
        try:
            line = p1.stdout.readline()
            if "ready" not in line:
                raise RuntimeError(f"{who}: first process failed to start: {line!r}")
            p2 = subprocess.Popen(second[0], env=second[1], stdout=subprocess.PIPE,
                                  stderr=subprocess.DEVNULL, text=True)
            try:
                out2, _ = p2.communicate(timeout=timeout)
                out1 = p1.stdout.readline() if first_measures else ""
            finally:
                if p2.poll() is None:
                    p2.kill()
            results = {}
            for text in (out2, out1):
                for raw in text.splitlines():
                    if raw.startswith("{"):
                        results.update(json.loads(raw))
            return results
        finally:
            try:
                p1.terminate()
                p1.wait(5)
            except subprocess.TimeoutExpired:
                p1.kill()

    def latency(self, who: str, queue: str, placement: str = ""):
        """Median round trip; ``placement`` "same" pins both processes to CPU 0, "split" to CPUs
        0 and 1 (the kernel's choice otherwise, which on a VM decides a wake-up's cost)."""
        if who in ("py-min", "raw", "raw-1"):
            if queue == "none":
                return None
            port = _free_port()
            kind = "raw" if who == "raw-1" else "raw-pubsub"
            extra = ["--messages"] if who == "py-min" else []
            first = self.command(who, f"{kind}-echo", ["--port", str(port), *extra])
            second = self.command(who, f"{kind}-ping", ["--port", str(port), *extra,
                                                        "--count", str(self.args.count)])
        elif who == "roscpp":
            if queue == "none":
                return None
            first = self.command(who, "", ["echo", "small", "10", "0", "0"])
            second = self.command(who, "", ["ping", "small", "10", "0", str(self.args.count)])
        else:
            first = self.command(who, "echo", ["--queue", queue])
            second = self.command(who, "ping", ["--queue", queue, "--count", str(self.args.count)])
        if placement:
            first, second = _pinned(first, 0), _pinned(second, 0 if placement == "same" else 1)
        r = self.pair(who, first, second)
        if "cpu_us" in r:
            key = queue + placement + ("shm" if self.shm else "")
            self.cpu[(key, who)] = self.cpu.get((key, who), []) + [r["cpu_us"]]
        return r.get("median_us")

    def flood(self, who: str, kind: str, queue: str = "10"):
        if who in ("raw-1", "py-min"):  # a flood is one connection one way: "raw" already is the floor
            return None
        if who == "roscpp" and queue == "none":  # roscpp has no synchronous publish
            return None
        seconds = str(self.args.seconds)
        if who == "raw":
            port = _free_port()
            r = self.pair(who, self.command(who, "raw-flood-sub", ["--port", str(port)]),
                          self.command(who, "raw-flood-pub", ["--port", str(port), "--kind", kind,
                                                              "--seconds", seconds]),
                          first_measures=True)
        elif who == "roscpp":
            r = self.pair(who, self.command(who, "", ["flood-sub", kind, "10", seconds, "0"]),
                          self.command(who, "", ["flood-pub", kind, "10", seconds, "0"]),
                          first_measures=True)
        else:
            r = self.pair(who, self.command(who, "flood-sub", ["--kind", kind]),
                          self.command(who, "flood-pub", ["--kind", kind, "--queue", queue,
                                                          "--seconds", seconds]),
                          first_measures=True)
        if r.get("received") and "pub_cpu_s" in r and "sub_cpu_s" in r:
            key = f"{kind}{queue}{'shm' if self.shm else ''}"
            per = (r["pub_cpu_s"] + r["sub_cpu_s"]) / r["received"] * 1e6
            self.cpu[(key, who)] = self.cpu.get((key, who), []) + [per]
        return r.get("rate")

    def service(self, who: str, persistent: bool, placement: str = ""):
        if who in ("py-min", "raw", "raw-1"):
            return None
        # as many calls as the topic round trips (a short run measures the CPU waking up);
        # a quarter when every call opens a connection (each takes ten times longer)
        count = str(self.args.count if persistent else max(self.args.count // 4, 100))
        if who == "roscpp":
            first = self.command(who, "", ["srv-server", "x", "0", "0", "0"])
            second = self.command(who, "", ["srv-client", "persistent" if persistent else "plain",
                                            "0", "0", count])
        else:
            first = self.command(who, "srv-server", [])
            second = self.command(who, "srv-client", [*(["--persistent"] if persistent else []),
                                                      "--count", count])
        if placement:
            first, second = _pinned(first, 0), _pinned(second, 0 if placement == "same" else 1)
        r = self.pair(who, first, second)
        if "cpu_us" in r:
            key = ("srv" if persistent else "srvnew") + placement
            self.cpu[(key, who)] = self.cpu.get((key, who), []) + [r["cpu_us"]]
        return r.get("median_us")

    def _start_ready(self, who: str, command: tuple) -> subprocess.Popen:
        proc = subprocess.Popen(command[0], env=command[1], stdout=subprocess.PIPE,
                                stderr=subprocess.DEVNULL, stdin=subprocess.PIPE, text=True)
        line = proc.stdout.readline()
        if "ready" not in line:
            proc.kill()
            raise RuntimeError(f"{who}: worker failed to start: {line!r}")
        return proc

    @staticmethod
    def _stop(procs: list) -> None:
        for proc in procs:
            if proc.poll() is None:
                proc.terminate()
        for proc in procs:
            try:
                proc.wait(5)
            except subprocess.TimeoutExpired:
                proc.kill()

    def fanout(self, who: str, kind: str, subs: int = 8):
        """One publisher flooding ``subs`` subscriber processes: messages/s delivered in all."""
        if who in ("py-min", "raw", "raw-1"):
            return None
        seconds = str(self.args.seconds)
        if who == "roscpp":
            sub_cmd = self.command(who, "", ["flood-sub", kind, "10", seconds, "0"])
            pub_cmd = self.command(who, "", ["flood-pub", kind, "10", seconds, str(subs)])
        else:
            sub_cmd = self.command(who, "flood-sub", ["--kind", kind])
            pub_cmd = self.command(who, "flood-pub", ["--kind", kind, "--queue", "10",
                                                      "--seconds", seconds, "--subs", str(subs)])
        procs = []
        try:
            for _ in range(subs):
                procs.append(self._start_ready(who, sub_cmd))
            subprocess.run(pub_cmd[0], env=pub_cmd[1], stdout=subprocess.DEVNULL,
                           stderr=subprocess.DEVNULL, timeout=120)
            total = 0.0
            for proc in procs:
                out, _ = proc.communicate(timeout=60)
                for raw in out.splitlines():
                    if raw.startswith("{"):
                        total += json.loads(raw).get("rate", 0.0)
            return total
        finally:
            self._stop(procs)

    def subscriber_cpu(self, who: str):
        """% of one core a subscriber spends receiving a 1920x1080 bgr8 image topic at 30 Hz."""
        if who in ("py-min", "raw", "raw-1"):
            return None
        seconds = str(max(self.args.seconds, 3.0))
        if who == "roscpp":
            first = self.command(who, "", ["cpu-sub", "hd", "10", seconds, "0"])
            second = self.command(who, "", ["rate-pub", "hd", "10", seconds, "30"])
        else:
            first = self.command(who, "cpu-sub", ["--kind", "hd"])
            second = self.command(who, "rate-pub", ["--kind", "hd", "--hz", "30", "--seconds", seconds])
        return self.pair(who, first, second, first_measures=True).get("cpu_percent")

    def shared(self, who: str, measure):
        """``measure()`` with minros on shared memory; the raw TCP floor beside it, nothing
        for contenders without shared memory."""
        if who in ("rospy", "roscpp", "py-min", "raw-1"):
            return None
        self.shm = who != "raw"
        try:
            return measure()
        finally:
            self.shm = False

    def intra(self, who: str, kind: str):
        """Frames/s one minros process delivers to itself with intraprocess=True."""
        if who not in ("minros", "baseline"):
            return None
        command, env = self.command(who, "intra-flood", ["--kind", kind, "--queue", "10",
                                                        "--seconds", str(self.args.seconds)])
        out = subprocess.run(command, env=env, capture_output=True, text=True, timeout=120).stdout
        for raw in out.splitlines():
            if raw.startswith("{"):
                return json.loads(raw).get("rate")
        return None

    def bringup(self, who: str, nodes: int = 100, topics: int = 10):
        """Seconds from starting ``nodes`` nodes (``topics`` publishers and subscribers each, in a
        ring) until every one of their connections is made."""
        if who not in ("minros", "rospy", "baseline"):
            return None
        procs = []
        start = time.time()
        try:
            for i in range(nodes):
                cmd = self.command(who, "ring-node", ["--index", str(i), "--nodes", str(nodes),
                                                      "--topics", str(topics)])
                procs.append(subprocess.Popen(cmd[0], env=cmd[1], stdout=subprocess.PIPE,
                                              stderr=subprocess.DEVNULL, stdin=subprocess.PIPE,
                                              text=True))
            done = []
            missing = 0
            for proc in procs:
                line = proc.stdout.readline()
                if not line.startswith("{"):
                    raise RuntimeError(f"{who}: a ring node failed")
                report = json.loads(line)
                missing += report.get("missing", 0)
                done.append(report.get("connected", 0.0))
            if missing:
                raise RuntimeError(f"{missing} of {nodes * topics} subscriptions never connected "
                                   f"within {RING_TIMEOUT:.0f} s")
            return max(done) - start
        finally:
            for proc in procs:
                try:
                    proc.stdin.close()
                except OSError:
                    pass
            self._stop(procs)

    def tool_cpu(self, who: str, verb: str):
        """% of one core ``rostopic hz|echo`` spends on a 10 kHz std_msgs/String topic (the same
        minros publisher for every tool)."""
        if who not in ("minros", "rospy", "baseline"):
            return None
        tool_env = self.env(who == "rospy")
        if who == "rospy":
            tool = [REFERENCE_PYTHON, "/usr/bin/rostopic", verb, "/bench_rate"]
        else:  # minros's tool, of this tree or the baseline's (its interpreter and path)
            (python, *_), tool_env = self.command(who, "", [])
            tool = [python, "-m", "minros", "topic", verb, "/bench_rate"]
        seconds = max(self.args.seconds, 3.0)
        procs = []
        try:
            procs.append(subprocess.Popen(tool, env=tool_env, stdout=subprocess.DEVNULL,
                                          stderr=subprocess.DEVNULL))
            pub_cmd = self.command("minros", "rate-pub", ["--kind", "small", "--hz", "10000",
                                                         "--seconds", str(seconds + 1.0)])
            pub = subprocess.Popen(pub_cmd[0], env=pub_cmd[1], stdout=subprocess.PIPE,
                                   stderr=subprocess.DEVNULL, text=True)
            procs.append(pub)
            if "started" not in pub.stdout.readline():
                raise RuntimeError("the 10 kHz publisher did not start")
            time.sleep(1.0)  # the tool's start-up is not what this measures
            before, t0 = _cpu_seconds(procs[0].pid), time.perf_counter()
            time.sleep(seconds - 1.0)
            after, t1 = _cpu_seconds(procs[0].pid), time.perf_counter()
            return 100.0 * (after - before) / (t1 - t0)
        finally:
            self._stop(procs)

    def idle_memory(self, who: str):
        if who in ("py-min", "raw", "raw-1", "roscpp"):
            return None
        code = ("import rospy, time\nrospy.init_node('bench_idle', anonymous=True)\ntime.sleep(1.0)\n"
                "print([l.split()[1] for l in open('/proc/self/status') if l.startswith('VmRSS')][0])\n")
        command, env = self.command(who, "", [])
        out = subprocess.run([command[0], "-c", code], env=env, capture_output=True,
                             text=True, timeout=60).stdout.split()
        return float(out[-1]) / 1024 if out else None

    def close(self) -> None:
        self.master.terminate()
        try:
            self.master.wait(5)
        except subprocess.TimeoutExpired:
            self.master.kill()
        shutil.rmtree(self.home, ignore_errors=True)


SCENARIOS = [
    ("round trip, queue_size=10 (µs)", "lat10", lambda r, w: r.latency(w, "10"), "low"),
    ("round trip, queue_size=None (µs)", "latnone", lambda r, w: r.latency(w, "none"), "low"),
    ("round trip, q=10, both processes on one CPU (µs)", "lat10same",
     lambda r, w: r.latency(w, "10", "same"), "low"),
    ("round trip, q=10, processes on different CPUs (µs)", "lat10split",
     lambda r, w: r.latency(w, "10", "split"), "low"),
    ("small-message flood (msg/s received)", "flood", lambda r, w: r.flood(w, "small"), "high"),
    ("640x480 bgr8 images (frames/s)", "vga", lambda r, w: r.flood(w, "vga"), "high"),
    ("1920x1080 bgr8 images (frames/s)", "hd", lambda r, w: r.flood(w, "hd"), "high"),
    ("1920x1080 bgr8, shared memory (frames/s)", "hdshm",
     lambda r, w: r.shared(w, lambda: r.flood(w, "hd")), "high"),
    ("1920x1080, publisher queue_size=None (frames/s)", "hdsync",
     lambda r, w: r.flood(w, "hd", "none"), "high"),
    ("3840x2160 bgr8 images (frames/s)", "4k", lambda r, w: r.flood(w, "4k"), "high"),
    ("3840x2160 bgr8, shared memory (frames/s)", "4kshm",
     lambda r, w: r.shared(w, lambda: r.flood(w, "4k")), "high"),
    ("20 MB PointCloud2 (clouds/s)", "cloud", lambda r, w: r.flood(w, "cloud"), "high"),
    ("20 MB PointCloud2, shared memory (clouds/s)", "cloudshm",
     lambda r, w: r.shared(w, lambda: r.flood(w, "cloud")), "high"),
    ("small-message flood, shared memory (msg/s received)", "floodshm",
     lambda r, w: r.shared(w, lambda: r.flood(w, "small")), "high"),
    ("round trip, q=10, shared memory (µs)", "lat10shm",
     lambda r, w: r.shared(w, lambda: r.latency(w, "10")), "low"),
    ("1920x1080 bgr8, intra-process (frames/s)", "hdintra", lambda r, w: r.intra(w, "hd"), "high"),
    ("idle node memory (MB RSS)", "mem", lambda r, w: r.idle_memory(w), "low"),
    ("service call, persistent (µs)", "srv", lambda r, w: r.service(w, True), "low"),
    ("service call, persistent, one CPU (µs)", "srvsame", lambda r, w: r.service(w, True, "same"), "low"),
    ("service call, persistent, different CPUs (µs)", "srvsplit",
     lambda r, w: r.service(w, True, "split"), "low"),
    ("service call, new connection each (µs)", "srvnew", lambda r, w: r.service(w, False), "low"),
    ("1 publisher -> 8 subscribers, small (msg/s delivered)", "fan", lambda r, w: r.fanout(w, "small"), "high"),
    ("1 publisher -> 8 subscribers, 640x480 (frames/s delivered)", "fanvga",
     lambda r, w: r.fanout(w, "vga"), "high"),
    ("subscriber CPU, 1920x1080 at 30 Hz (% of a core)", "subcpu", lambda r, w: r.subscriber_cpu(w), "low"),
    ("subscriber CPU, 1920x1080 at 30 Hz, shared memory (% of a core)", "subcpushm",
     lambda r, w: r.shared(w, lambda: r.subscriber_cpu(w)), "low"),
    ("100 nodes x 10 topics: all connected (s)", "bringup", lambda r, w: r.bringup(w), "low"),
    ("rostopic hz, 10 kHz topic (% of a core)", "hz", lambda r, w: r.tool_cpu(w, "hz"), "low"),
    ("rostopic echo, 10 kHz topic (% of a core)", "echo", lambda r, w: r.tool_cpu(w, "echo"), "low"),
]


def _fmt(value) -> str:
    if value is None:
        return "—"
    return f"{value:,.0f}" if value >= 100 else f"{value:.1f}"


def _own_ratios(med: dict, contenders: list) -> list:
    """minros+trace/minros (the trace's cost) and minros/baseline (two versions)."""
    cells = []
    for other in ("minros+trace", "baseline"):
        if other in contenders:
            top, bottom = (other, "minros") if other == "minros+trace" else ("minros", other)
            ok = med.get(top) and med.get(bottom)
            cells.append(f"{med[top] / med[bottom]:.2f}x" if ok else "—")
    return cells


def _load() -> str:
    """The 1-minute load average (other users of a shared machine show here)."""
    try:
        return f"{os.getloadavg()[0]:.2f}"
    except OSError:
        return "?"


def machine() -> str:
    """The CPU model (from /proc/cpuinfo) and the kernel: per-call costs depend on both."""
    model = "unknown CPU"
    try:
        with open("/proc/cpuinfo") as f:
            for line in f:
                if line.startswith("model name"):
                    model = line.partition(":")[2].strip()
                    break
    except OSError:
        pass
    return f"CPU: {model} x {os.cpu_count()}; kernel: {platform.system()} {platform.release()}"


def _python_version(python: str) -> str:
    out = subprocess.run([python, "-c", "import sys; print(sys.version.split()[0])"],
                         capture_output=True, text=True)
    return f"{python} {out.stdout.strip()}"


def baseline_env(checkout: str) -> dict:
    """What runs another checkout's minros with this venv's interpreter: its src/ and stubs/
    first on the path (before this checkout's editable install), and its bytecode in a cache
    of its own, outside it."""
    checkout = os.path.abspath(checkout)
    cache = os.path.join(tempfile.gettempdir(), "minros-bench-pycache",
                         hashlib.sha1(checkout.encode()).hexdigest()[:12])
    return {"PYTHONPATH": os.pathsep.join(os.path.join(checkout, d) for d in ("src", "stubs")),
            "PYTHONPYCACHEPREFIX": cache}


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--role", choices=sorted(ROLES), help=argparse.SUPPRESS)
    parser.add_argument("--queue", default="10", help=argparse.SUPPRESS)
    parser.add_argument("--kind", default="small", help=argparse.SUPPRESS)
    parser.add_argument("--port", type=int, default=0, help=argparse.SUPPRESS)
    parser.add_argument("--messages", action="store_true", help=argparse.SUPPRESS)
    parser.add_argument("--persistent", action="store_true", help=argparse.SUPPRESS)
    parser.add_argument("--subs", type=int, default=1, help=argparse.SUPPRESS)
    parser.add_argument("--hz", type=float, default=30.0, help=argparse.SUPPRESS)
    parser.add_argument("--index", type=int, default=0, help=argparse.SUPPRESS)
    parser.add_argument("--nodes", type=int, default=100, help=argparse.SUPPRESS)
    parser.add_argument("--topics", type=int, default=10, help=argparse.SUPPRESS)
    parser.add_argument("--rounds", type=int, default=3, help="interleaved rounds (median shown)")
    parser.add_argument("--seconds", type=float, default=2.0, help="duration of each flood")
    parser.add_argument("--count", type=int, default=2000, help="round trips per latency run")
    parser.add_argument("--only", default="", help="comma-separated contenders")
    parser.add_argument("--minros-python", default=VENV_PYTHON,
                        help="interpreter of the minros and raw workers (default: the venv's)")
    parser.add_argument("--scenarios", default="", help="comma-separated: " +
                        ",".join(s[1] for s in SCENARIOS))
    parser.add_argument("--trace", action="store_true",
                        help="add minros+trace: minros writing a wire trace of every frame")
    parser.add_argument("--baseline", default="", metavar="PY|DIR",
                        help="add 'baseline': minros run by this interpreter (another checkout's "
                             "venv), or the checkout DIR's src/ and stubs/ run by the minros "
                             "workers' interpreter")
    args = parser.parse_args(argv)
    if args.role:
        ROLES[args.role](args)
        return 0
    byte_compile_minros()
    if args.baseline and os.path.isdir(args.baseline):  # a checkout: compiled where it runs
        subprocess.run([args.minros_python, "-c", "import compileall, sys; [compileall.compile_dir("
                        "d, quiet=1) for d in sys.argv[1:]]",
                        *(os.path.join(args.baseline, d) for d in ("src", "stubs"))],
                       env=dict(os.environ, **baseline_env(args.baseline)), check=True)
    elif args.baseline:  # its checkout, when the interpreter is that checkout's .venv
        byte_compile_minros(os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(args.baseline)))))
    load = (_load(),)
    runner = Runner(args)
    try:
        contenders = runner.contenders()
        scenarios = [s for s in SCENARIOS if not args.scenarios or s[1] in args.scenarios.split(",")]
        results = {(s[1], c): [] for s in scenarios for c in contenders}
        failures: list = []  # runs that gave no figure: listed under the table
        for rnd in range(args.rounds):
            for _title, key, fn, _better in scenarios:
                for who in contenders:  # interleaved: every contender once per round
                    try:
                        value = fn(runner, who)
                    except Exception as exc:  # one failed run must not lose the table
                        print(f"  {who} {key}: failed: {exc}", file=sys.stderr)
                        failures.append(f"round {rnd + 1}, {key}, {who}: {exc}")
                        value = None
                    if value is not None:
                        results[(key, who)].append(value)
                    print(f"round {rnd + 1} {key:8} {who:7} {_fmt(value)}", file=sys.stderr, flush=True)
        header = ["scenario", *contenders]
        for other in ("minros+trace", "baseline"):
            if other in contenders:
                header.append(f"{other}/minros" if other == "minros+trace" else "minros/baseline")
        if "rospy" in contenders:
            header.append("minros/rospy")
        for other in ("py-min", "raw", "raw-1"):
            if other in contenders:
                header.append(f"minros/{other}")
        rows = []
        # CPU time (steadier than wall-clock latency on a loaded or idle machine) follows its scenario
        cpu_rows = {"lat10": ("10", "CPU per round trip, ping side, q=10 (µs)"),
                    "lat10same": ("10same", "CPU per round trip, one CPU (µs)"),
                    "lat10split": ("10split", "CPU per round trip, different CPUs (µs)"),
                    "flood": ("small10", "CPU per message received, both processes (µs)"),
                    "vga": ("vga10", "CPU per frame received, both processes (µs)"),
                    "hd": ("hd10", "CPU per frame received, both processes (µs)"),
                    "hdshm": ("hd10shm", "CPU per frame received, both processes (µs)"),
                    "hdsync": ("hdnone", "CPU per frame received, both processes (µs)"),
                    "4k": ("4k10", "CPU per frame received, both processes (µs)"),
                    "4kshm": ("4k10shm", "CPU per frame received, both processes (µs)"),
                    "cloud": ("cloud10", "CPU per cloud received, both processes (µs)"),
                    "cloudshm": ("cloud10shm", "CPU per cloud received, both processes (µs)"),
                    "floodshm": ("small10shm", "CPU per message received, both processes (µs)"),
                    "lat10shm": ("10shm", "CPU per round trip, ping side, shared memory (µs)"),
                    "srv": ("srv", "CPU per persistent call, client side (µs)"),
                    "srvsame": ("srvsame", "CPU per persistent call, one CPU (µs)"),
                    "srvsplit": ("srvsplit", "CPU per persistent call, different CPUs (µs)"),
                    "srvnew": ("srvnew", "CPU per new-connection call, client side (µs)")}

        def ratio_row(title: str, med: dict) -> list:
            row = [title] + [_fmt(med[c]) for c in contenders] + _own_ratios(med, contenders)
            for other in ("rospy", "py-min", "raw", "raw-1"):
                if other in contenders:
                    ok = med.get("minros") and med.get(other)
                    row.append(f"{med['minros'] / med[other]:.2f}x" if ok else "—")
            return row

        for title, key, _fn, _better in scenarios:
            rows.append(ratio_row(title, {c: statistics.median(results[(key, c)])
                                          if results[(key, c)] else None for c in contenders}))
            cpu_key, cpu_title = cpu_rows.get(key, (None, ""))
            if cpu_key and any(runner.cpu.get((cpu_key, c)) for c in contenders):
                rows.append(ratio_row(cpu_title, {c: statistics.median(runner.cpu[(cpu_key, c)])
                                                  if runner.cpu.get((cpu_key, c)) else None
                                                  for c in contenders}))
        widths = [max(len(str(r[i])) for r in [header] + rows) for i in range(len(header))]
        print(f"pubsub benchmark: {args.rounds} interleaved rounds, median; master: "
              f"{'Debian rosmaster' if runner.reference else 'minros'}; {os.cpu_count()} CPUs; "
              f"minros on {_python_version(args.minros_python)}, rospy on "
              f"{_python_version(REFERENCE_PYTHON) if runner.reference else '-'}")
        print("| " + " | ".join(h.ljust(w) for h, w in zip(header, widths)) + " |")
        print("|" + "|".join("-" * (w + 2) for w in widths) + "|")
        for row in rows:
            print("| " + " | ".join(str(c).ljust(w) for c, w in zip(row, widths)) + " |")
        print(machine() + f"; load average before/after: {load[0]} / {_load()}")
        if failures:
            print("\nruns without a figure (the medians above are of the other rounds):")
            for line in failures:
                print(f"  {line}")
    finally:
        runner.close()
    return 0


if __name__ == "__main__":
    sys.exit(main())
