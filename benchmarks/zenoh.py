#!/usr/bin/env python3
"""``minros zenoh`` beside TCPROS, in one run: round trip, 1080p frames/s, discovery, loss.

    .venv/bin/python benchmarks/zenoh.py [--rounds 3] [--seconds 3] [--count 2000]

Two minros masters on loopback, each with its bridge (a listens on a loopback port, b
connects; no multicast). Contenders, interleaved round by round (the machine is shared: the
table shows medians of the rounds):

* round trip of a 20-byte std_msgs/String, each side answering from its receive callback:
  "TCPROS" with both nodes on master a; "2 bridges" with the pinger on a and the echo on b
  (ping: ROS -> bridge a -> Zenoh -> bridge b -> ROS, and the pong back the same way);
  "Zenoh floor" is two plain zenoh-python sessions echoing the bytes, the least any bridge
  on eclipse-zenoh can do;
* 1920x1080 rgb8 sensor_msgs/Image flood (publisher queue_size=10), frames/s received:
  TCPROS on one master, and through the two bridges;
* discovery: seconds from a new publisher's Publisher() on a until master b lists the topic
  (bridge b advertised it);
* loss: seconds from SIGKILL of bridge a until master b no longer lists a topic bridge b was
  publishing for it (its beacons stopped; bridge a is started again for the next round).

This file is also the worker: ``--role ...`` runs one side and prints one JSON line.
"""

from __future__ import annotations

import argparse
import json
import os
import signal
import statistics
import subprocess
import sys
import tempfile
import threading
import time
import xmlrpc.client

HERE = os.path.dirname(os.path.abspath(__file__))
REPO = os.path.dirname(HERE)
PYTHON = sys.executable
# this file is benchmarks/zenoh.py: its folder must not shadow the zenoh package
sys.path[:] = [p for p in sys.path if os.path.abspath(p or os.curdir) != HERE]

# ------------------------------------------------------------------------------------ workers


def _init(name: str):
    import warnings

    import rospy

    warnings.simplefilter("ignore", SyntaxWarning)
    rospy.init_node(name, anonymous=True)
    return rospy


def role_echo(args) -> None:
    rospy = _init("zb_echo")
    from std_msgs.msg import String

    pub = rospy.Publisher(args.pong, String, queue_size=10, tcp_nodelay=True)
    rospy.Subscriber(args.ping, String, pub.publish, tcp_nodelay=True)
    print(json.dumps({"ready": True}), flush=True)
    rospy.spin()


def role_ping(args) -> None:
    rospy = _init("zb_ping")
    from std_msgs.msg import String

    pub = rospy.Publisher(args.ping, String, queue_size=10, tcp_nodelay=True)
    msg = String("x" * 16)
    got = threading.Event()
    rospy.Subscriber(args.pong, String, lambda _m: got.set(), tcp_nodelay=True)
    deadline = time.monotonic() + 30
    while not got.is_set():  # until the whole path answers (bridges made, connections up)
        if time.monotonic() > deadline:
            raise SystemExit("no pong within 30 s")
        pub.publish(msg)
        got.wait(0.05)
    time.sleep(0.3)
    times = []
    for i in range(args.count + 200):
        got.clear()
        t = time.perf_counter()
        pub.publish(msg)
        if not got.wait(2.0):
            continue
        if i >= 200:
            times.append(time.perf_counter() - t)
    times.sort()
    print(json.dumps({"median_us": statistics.median(times) * 1e6,
                      "p95_us": times[int(len(times) * 0.95)] * 1e6, "n": len(times)}), flush=True)
    rospy.signal_shutdown("done")


def _image():
    from sensor_msgs.msg import Image

    return Image, Image(height=1080, width=1920, encoding="rgb8", step=5760,
                        data=bytes(1920 * 1080 * 3))


def role_flood_pub(args) -> None:
    rospy = _init("zb_flood_pub")
    cls, msg = _image()
    pub = rospy.Publisher(args.topic, cls, queue_size=10)
    deadline = time.monotonic() + 30
    while pub.get_num_connections() < 1:
        if time.monotonic() > deadline:
            raise SystemExit("no subscriber")
        time.sleep(0.01)
    print(json.dumps({"ready": True}), flush=True)
    end = time.monotonic() + args.seconds + 30
    while time.monotonic() < end and not rospy.is_shutdown():
        pub.publish(msg)


def role_flood_sub(args) -> None:
    rospy = _init("zb_flood_sub")
    cls, _ = _image()
    stamps: list = []
    rospy.Subscriber(args.topic, cls, lambda _m: stamps.append(time.perf_counter()),
                     queue_size=None, buff_size=1 << 24)
    deadline = time.monotonic() + 40
    while len(stamps) < 20:  # warm up: the flow is established
        if time.monotonic() > deadline:
            raise SystemExit("no frames")
        time.sleep(0.01)
    start = len(stamps)
    time.sleep(args.seconds)
    end = len(stamps)
    rate = (end - start - 1) / (stamps[end - 1] - stamps[start]) if end - start > 1 else 0.0
    print(json.dumps({"rate": rate}), flush=True)
    rospy.signal_shutdown("done")


def role_advertise(args) -> None:
    rospy = _init("zb_new_topic")
    from std_msgs.msg import String

    sys.stdin.readline()  # go
    t = time.time()
    pub = rospy.Publisher(args.topic, String, queue_size=1)
    print(json.dumps({"advertised": t}), flush=True)
    sys.stdin.readline()  # stop
    pub.unregister()


def _zenoh_session(listen=None, connect=None):
    import zenoh

    config = zenoh.Config()
    config.insert_json5("scouting/multicast/enabled", "false")
    if listen:
        config.insert_json5("listen/endpoints", json.dumps([listen]))
    if connect:
        config.insert_json5("connect/endpoints", json.dumps([connect]))
    return zenoh.open(config)


def role_zpong(args) -> None:
    import zenoh

    session = _zenoh_session(listen=args.endpoint)
    pub = session.declare_publisher("zb/pong", congestion_control=zenoh.CongestionControl.BLOCK,
                                    express=True)
    session.declare_subscriber("zb/ping", lambda s: pub.put(s.payload.to_bytes()))
    print(json.dumps({"ready": True}), flush=True)
    sys.stdin.readline()


def role_zping(args) -> None:
    import zenoh

    session = _zenoh_session(connect=args.endpoint)
    pub = session.declare_publisher("zb/ping", congestion_control=zenoh.CongestionControl.BLOCK,
                                    express=True)
    got = threading.Event()
    session.declare_subscriber("zb/pong", lambda _s: got.set())
    payload = b"\x10\x00\x00\x00" + b"x" * 16
    deadline = time.monotonic() + 20
    while not got.is_set():
        if time.monotonic() > deadline:
            raise SystemExit("no zenoh pong")
        pub.put(payload)
        got.wait(0.05)
    times = []
    for i in range(args.count + 200):
        got.clear()
        t = time.perf_counter()
        pub.put(payload)
        if got.wait(2.0) and i >= 200:
            times.append(time.perf_counter() - t)
    times.sort()
    print(json.dumps({"median_us": statistics.median(times) * 1e6,
                      "p95_us": times[int(len(times) * 0.95)] * 1e6, "n": len(times)}), flush=True)


ROLES = {"echo": role_echo, "ping": role_ping, "flood_pub": role_flood_pub,
         "flood_sub": role_flood_sub, "advertise": role_advertise, "zpong": role_zpong,
         "zping": role_zping}

# ------------------------------------------------------------------------------------- runner


def _free_port() -> int:
    import socket

    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


class Site:
    def __init__(self, name: str, home: str) -> None:
        self.port = _free_port()
        self.home = os.path.join(home, name)
        os.makedirs(os.path.join(self.home, "log"))
        self.env = {k: v for k, v in os.environ.items() if not k.startswith("ROS_")}
        self.env.update(ROS_MASTER_URI=f"http://localhost:{self.port}", ROS_HOSTNAME="localhost",
                        ROS_HOME=self.home, ROS_LOG_DIR=os.path.join(self.home, "log"),
                        PYTHONUNBUFFERED="1")
        self.master = self.spawn([PYTHON, "-m", "minros.master", "-p", str(self.port)])
        self.bridge = None
        deadline = time.monotonic() + 20
        while True:
            try:
                xmlrpc.client.ServerProxy(f"http://localhost:{self.port}/").getPid("/b")
                break
            except OSError:
                if time.monotonic() > deadline:
                    raise
                time.sleep(0.05)

    def spawn(self, argv, stdin=subprocess.DEVNULL) -> subprocess.Popen:
        return subprocess.Popen(argv, env=self.env, stdin=stdin, stdout=subprocess.PIPE,
                                stderr=subprocess.DEVNULL, text=True, start_new_session=True)

    def role(self, role: str, *args: str, stdin=subprocess.DEVNULL) -> subprocess.Popen:
        return self.spawn([PYTHON, os.path.abspath(__file__), "--role", role, *args], stdin=stdin)

    def start_bridge(self, *args: str) -> None:
        self.bridge_args = args
        self.bridge = self.spawn([PYTHON, "-m", "minros", "zenoh", "--no-multicast-scouting", *args])
        line = self.bridge.stdout.readline()
        if "bridging the master" not in line:
            raise SystemExit(f"bridge did not start: {line}")
        # drain its log so that it never blocks on a full pipe
        threading.Thread(target=self.bridge.stdout.read, daemon=True).start()

    def published(self, topic: str, by: str = "") -> bool:
        pubs = xmlrpc.client.ServerProxy(self.env["ROS_MASTER_URI"]).getSystemState("/b")[2][0]
        return any(t == topic and (not by or by in nodes) for t, nodes in pubs)


def _stop(proc) -> None:
    if proc is None or proc.poll() is not None:
        return
    for sig in (signal.SIGINT, signal.SIGKILL):
        try:
            os.killpg(proc.pid, sig)
            proc.wait(5)
            return
        except (ProcessLookupError, subprocess.TimeoutExpired):
            continue


def _result(proc, timeout: float = 120) -> dict:
    out, _ = proc.communicate(timeout=timeout)
    lines = [line for line in out.splitlines() if line.startswith("{")]
    if not lines:
        raise SystemExit(f"worker printed nothing: {proc.args}")
    return json.loads(lines[-1])


def rtt(a: Site, b: Site, where: str, count: int, n: int) -> float:
    ping, pong = f"/zb_ping_{n}", f"/zb_pong_{n}"
    echo_site = a if where == "TCPROS" else b
    echo = echo_site.role("echo", "--ping", ping, "--pong", pong)
    try:
        echo.stdout.readline()
        return _result(a.role("ping", "--ping", ping, "--pong", pong, "--count", str(count)))["median_us"]
    finally:
        _stop(echo)


def zenoh_floor(count: int) -> float:
    endpoint = f"tcp/127.0.0.1:{_free_port()}"
    env = dict(os.environ)
    pong = subprocess.Popen([PYTHON, __file__, "--role", "zpong", "--endpoint", endpoint],
                            stdin=subprocess.PIPE, stdout=subprocess.PIPE, text=True, env=env)
    try:
        pong.stdout.readline()
        ping = subprocess.run([PYTHON, __file__, "--role", "zping", "--endpoint", endpoint,
                               "--count", str(count)], capture_output=True, text=True, timeout=120)
        return json.loads(ping.stdout.strip().splitlines()[-1])["median_us"]
    finally:
        pong.stdin.close()
        pong.wait(10)


def flood(a: Site, b: Site, where: str, seconds: float, n: int) -> float:
    topic = f"/zb_image_{n}"
    sub = (a if where == "TCPROS" else b).role("flood_sub", "--topic", topic, "--seconds", str(seconds))
    pub = a.role("flood_pub", "--topic", topic, "--seconds", str(seconds))
    try:
        return _result(sub)["rate"]
    finally:
        _stop(pub)
        _stop(sub)


def discovery(a: Site, b: Site, n: int) -> float:
    topic = f"/zb_new_{n}"
    adv = a.role("advertise", "--topic", topic, stdin=subprocess.PIPE)
    try:
        time.sleep(1.0)  # the node is up
        adv.stdin.write("go\n")
        adv.stdin.flush()
        t0 = json.loads(adv.stdout.readline())["advertised"]
        deadline = time.time() + 10
        while not b.published(topic, "/minros_zenoh"):
            if time.time() > deadline:
                return float("nan")
            time.sleep(0.005)
        return time.time() - t0
    finally:
        adv.stdin.write("stop\n")
        adv.stdin.flush()
        _stop(adv)


def loss(a: Site, b: Site, n: int) -> float:
    topic = f"/zb_loss_{n}"
    adv = a.role("advertise", "--topic", topic, stdin=subprocess.PIPE)
    try:
        time.sleep(1.0)
        adv.stdin.write("go\n")
        adv.stdin.flush()
        adv.stdout.readline()
        deadline = time.time() + 10
        while not b.published(topic, "/minros_zenoh"):
            if time.time() > deadline:
                return float("nan")
            time.sleep(0.01)
        time.sleep(1.0 + (n % 10) / 10)  # anywhere in the beacon period
        t0 = time.time()
        os.killpg(a.bridge.pid, signal.SIGKILL)
        a.bridge.wait(5)
        while b.published(topic, "/minros_zenoh"):
            if time.time() - t0 > 15:
                return float("nan")
            time.sleep(0.005)
        return time.time() - t0
    finally:
        adv.stdin.write("stop\n")
        adv.stdin.flush()
        _stop(adv)
        a.start_bridge(*a.bridge_args)


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--role", choices=sorted(ROLES))
    parser.add_argument("--ping", default="/zb_ping")
    parser.add_argument("--pong", default="/zb_pong")
    parser.add_argument("--topic", default="/zb_image")
    parser.add_argument("--endpoint", default="")
    parser.add_argument("--count", type=int, default=2000)
    parser.add_argument("--seconds", type=float, default=3.0)
    parser.add_argument("--rounds", type=int, default=3)
    args = parser.parse_args(argv)
    if args.role:
        ROLES[args.role](args)
        return 0
    signal.signal(signal.SIGTERM, lambda *_: sys.exit(1))  # stopped: the finally below cleans up
    home = tempfile.mkdtemp(prefix="zenoh-bench-")
    a, b = Site("a", home), Site("b", home)
    endpoint = f"tcp/127.0.0.1:{_free_port()}"
    results: dict = {}
    try:
        a.start_bridge("--listen", endpoint)
        b.start_bridge("--connect", endpoint)
        for r in range(args.rounds):
            for where in ("TCPROS", "2 bridges"):
                results.setdefault(("rtt", where), []).append(rtt(a, b, where, args.count, r))
            results.setdefault(("rtt", "Zenoh floor"), []).append(zenoh_floor(args.count))
            for where in ("TCPROS", "2 bridges"):
                results.setdefault(("hd", where), []).append(flood(a, b, where, args.seconds, r))
            results.setdefault(("discovery", "2 bridges"), []).append(discovery(a, b, r))
            results.setdefault(("loss", "2 bridges"), []).append(loss(a, b, r))
            print(f"round {r + 1}/{args.rounds} done", file=sys.stderr, flush=True)
    finally:
        for site in (b, a):
            _stop(site.bridge)
            _stop(site.master)
    rows = [("small-message round trip (us)", "rtt", "<= 300"),
            ("1920x1080 rgb8 frames/s received", "hd", ">= 300"),
            ("new remote topic listed after (s)", "discovery", "<= 1.5"),
            ("remote loss noticed after (s)", "loss", "<= 3.5")]
    load = os.getloadavg()[0]
    print(f"\nminros zenoh vs TCPROS, median of {args.rounds} interleaved rounds "
          f"(python {sys.version.split()[0]}, {os.cpu_count()} CPUs, load average {load:.1f})\n")
    print(f"{'measure':36} {'TCPROS':>10} {'2 bridges':>10} {'Zenoh floor':>12} {'target':>8}")
    for title, kind, target in rows:
        cells = []
        for where in ("TCPROS", "2 bridges", "Zenoh floor"):
            values = results.get((kind, where))
            cells.append(f"{statistics.median(values):.3g}" if values else "-")
        print(f"{title:36} {cells[0]:>10} {cells[1]:>10} {cells[2]:>12} {target:>8}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
