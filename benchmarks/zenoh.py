#!/usr/bin/env python3
"""``minros zenoh`` beside TCPROS, in one run: round trip, 1080p frames/s, discovery, loss.

    .venv/bin/python benchmarks/zenoh.py [--rounds 3] [--seconds 3] [--count 2000]
        [--only rtt,hd,discovery,loss] [--baseline OTHER_CHECKOUT/.venv/bin/python]

Two minros masters on loopback, each with its bridge (a listens on a loopback port, b
connects; no multicast). Contenders, interleaved round by round (the machine is shared: the
table shows medians of the rounds):

* round trip of a 20-byte std_msgs/String, each side answering from its receive callback:
  "TCPROS" with both nodes on master a; "2 bridges" with the pinger on a and the echo on b
  (ping: ROS -> bridge a -> Zenoh -> bridge b -> ROS, and the pong back the same way);
  "Zenoh floor" is two plain zenoh-python sessions, configured and called as the bridge's,
  echoing the bytes: the least any bridge on eclipse-zenoh can do;
* 1920x1080 rgb8 sensor_msgs/Image flood (publisher queue_size=10), frames/s received:
  TCPROS on one master, through the two bridges, and between two plain zenoh-python
  sessions (the subscriber takes each sample's bytes, as the bridge must);
* discovery: seconds from a new publisher's Publisher() on a until master b lists the topic
  (bridge b advertised it);
* loss: seconds from SIGKILL of bridge a until master b no longer lists a topic bridge b was
  publishing for it (its beacons stopped; bridge a is started again for the next round).

Wall-clock figures move with the load of a shared machine; the CPU that each process (the
publisher, the subscriber, both bridges) spends per round trip or per frame moves much less,
and it is printed below the table: it shows where the time goes. ``--baseline PY`` adds two
more bridges run by another checkout's interpreter (their own masters and Zenoh link), so
two versions of the bridge meet in one run.

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

_TICK = os.sysconf("SC_CLK_TCK") if hasattr(os, "sysconf") else 100


def _cpu_seconds(pid: int) -> float:
    """User + system CPU of every thread of process ``pid`` so far (Linux /proc), or nan."""
    try:
        with open(f"/proc/{pid}/stat") as f:
            fields = f.read().rpartition(")")[2].split()
        return (int(fields[11]) + int(fields[12])) / _TICK
    except (OSError, IndexError, ValueError):
        return float("nan")


class _Watch:
    """CPU seconds of the processes named in ``--watch`` (label=pid,...) and this one, between
    ``start()`` and ``stop()``: what each process spends per message, whatever the load."""

    def __init__(self, spec: str, me: str) -> None:
        self.pids = {me: os.getpid()}
        for item in filter(None, spec.split(",")):
            label, _, pid = item.partition("=")
            self.pids[label] = int(pid)
        self.before: dict = {}

    def start(self) -> None:
        self.before = {label: _cpu_seconds(pid) for label, pid in self.pids.items()}

    def per(self, count: int) -> dict:
        """Milliseconds of CPU per one of ``count`` messages, by process."""
        return {label: (_cpu_seconds(pid) - self.before[label]) * 1e3 / max(count, 1)
                for label, pid in self.pids.items()}


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
    watch = _Watch(args.watch, "ping")
    times = []
    for i in range(args.count + 200):
        if i == 200:
            watch.start()
        got.clear()
        t = time.perf_counter()
        pub.publish(msg)
        if not got.wait(2.0):
            continue
        if i >= 200:
            times.append(time.perf_counter() - t)
    cpu = watch.per(args.count)
    times.sort()
    print(json.dumps({"median_us": statistics.median(times) * 1e6,
                      "p95_us": times[int(len(times) * 0.95)] * 1e6, "n": len(times),
                      "cpu_ms": cpu}), flush=True)
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
    period = 1.0 / args.pace if args.pace else 0.0
    due = time.monotonic()
    while time.monotonic() < end and not rospy.is_shutdown():
        pub.publish(msg)
        if period:  # paced: what a frame costs each process, below saturation
            due += period
            time.sleep(max(0.0, due - time.monotonic()))


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
    watch = _Watch(args.watch, "sub")
    start = len(stamps)
    watch.start()
    time.sleep(args.seconds)
    end = len(stamps)
    cpu = watch.per(end - start)
    rate = (end - start - 1) / (stamps[end - 1] - stamps[start]) if end - start > 1 else 0.0
    print(json.dumps({"rate": rate, "cpu_ms": cpu}), flush=True)
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
    """A plain session configured as the bridge's (its transport settings), no ROS."""
    import zenoh

    from minros.zenoh.bridge import Options, zenoh_config

    options = Options(listen=[listen] if listen else [], connect=[connect] if connect else [],
                      multicast_scouting=False)
    return zenoh.open(zenoh_config(options))


def role_zflood_sub(args) -> None:
    """The Zenoh floor of the 1080p flood: every sample's bytes taken into Python, as any
    Python consumer (and the bridge) must."""
    session = _zenoh_session(connect=args.endpoint)
    stamps: list = []

    def on_sample(sample) -> None:
        sample.payload.to_bytes()
        stamps.append(time.perf_counter())

    session.declare_subscriber("zb/image", on_sample)
    print(json.dumps({"ready": True}), flush=True)
    deadline = time.monotonic() + 40
    while len(stamps) < 20:
        if time.monotonic() > deadline:
            raise SystemExit("no zenoh frames")
        time.sleep(0.01)
    watch = _Watch(args.watch, "sub")
    start = len(stamps)
    watch.start()
    time.sleep(args.seconds)
    end = len(stamps)
    cpu = watch.per(end - start)
    rate = (end - start - 1) / (stamps[end - 1] - stamps[start]) if end - start > 1 else 0.0
    print(json.dumps({"rate": rate, "cpu_ms": cpu}), flush=True)
    session.close()


def role_zflood_pub(args) -> None:
    import zenoh

    session = _zenoh_session(listen=args.endpoint)
    pub = session.declare_publisher("zb/image", congestion_control=zenoh.CongestionControl.BLOCK,
                                    reliability=zenoh.Reliability.RELIABLE)
    data = _image()[1].data
    payload = b"\0" * 29 + data  # an Image's header fields, then its pixels
    end = time.monotonic() + args.seconds + 30
    period = 1.0 / args.pace if args.pace else 0.0
    due = time.monotonic()
    try:
        while time.monotonic() < end:
            pub.put(payload)
            if period:
                due += period
                time.sleep(max(0.0, due - time.monotonic()))
    except KeyboardInterrupt:  # the runner's stop
        pass


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
    watch = _Watch(args.watch, "ping")
    times = []
    for i in range(args.count + 200):
        if i == 200:
            watch.start()
        got.clear()
        t = time.perf_counter()
        pub.put(payload)
        if got.wait(2.0) and i >= 200:
            times.append(time.perf_counter() - t)
    cpu = watch.per(args.count)
    times.sort()
    print(json.dumps({"median_us": statistics.median(times) * 1e6,
                      "p95_us": times[int(len(times) * 0.95)] * 1e6, "n": len(times),
                      "cpu_ms": cpu}), flush=True)


ROLES = {"echo": role_echo, "ping": role_ping, "flood_pub": role_flood_pub,
         "flood_sub": role_flood_sub, "advertise": role_advertise, "zpong": role_zpong,
         "zping": role_zping, "zflood_pub": role_zflood_pub, "zflood_sub": role_zflood_sub}

# ------------------------------------------------------------------------------------- runner


def _free_port() -> int:
    import socket

    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


class Site:
    """A master, and the bridge its ``python`` runs (another checkout's for the baseline)."""

    def __init__(self, name: str, home: str, python: str = PYTHON) -> None:
        self.port = _free_port()
        self.python = python
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
        self.bridge = self.spawn([self.python, "-m", "minros", "zenoh", "--no-multicast-scouting",
                                  *args])
        line = self.bridge.stdout.readline()
        if "bridging the master" not in line:
            raise SystemExit(f"bridge did not start: {line}")
        # drain its log so that it never blocks on a full pipe
        threading.Thread(target=self.bridge.stdout.read, daemon=True).start()

    def published(self, topic: str, by: str = "") -> bool:
        pubs = xmlrpc.client.ServerProxy(self.env["ROS_MASTER_URI"]).getSystemState("/b")[2][0]
        return any(t == topic and (not by or by in nodes) for t, nodes in pubs)


class Pair:
    """Two sites joined by their bridges (a listens, b connects), or one site for TCPROS."""

    def __init__(self, a: Site, b: Site | None) -> None:
        self.a, self.b = a, b or a

    def start(self) -> None:
        if self.b is not self.a:
            endpoint = f"tcp/127.0.0.1:{_free_port()}"
            self.a.start_bridge("--listen", endpoint)
            self.b.start_bridge("--connect", endpoint)

    def watch(self, **pids: int) -> str:
        """``--watch`` of the bridges and the given workers."""
        if self.b is not self.a:
            pids.update(bridge_a=self.a.bridge.pid, bridge_b=self.b.bridge.pid)
        return ",".join(f"{label}={pid}" for label, pid in pids.items())

    def stop(self) -> None:
        for site in {id(s): s for s in (self.b, self.a)}.values():
            _stop(site.bridge)
            _stop(site.master)


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


def rtt(pair: Pair, count: int, n: int) -> dict:
    ping, pong = f"/zb_ping_{n}", f"/zb_pong_{n}"
    echo = pair.b.role("echo", "--ping", ping, "--pong", pong)
    try:
        echo.stdout.readline()
        return _result(pair.a.role("ping", "--ping", ping, "--pong", pong, "--count", str(count),
                                   "--watch", pair.watch(echo=echo.pid)))
    finally:
        _stop(echo)


def zenoh_floor(count: int) -> dict:
    endpoint = f"tcp/127.0.0.1:{_free_port()}"
    env = dict(os.environ)
    pong = subprocess.Popen([PYTHON, __file__, "--role", "zpong", "--endpoint", endpoint],
                            stdin=subprocess.PIPE, stdout=subprocess.PIPE, text=True, env=env)
    try:
        pong.stdout.readline()
        ping = subprocess.run([PYTHON, __file__, "--role", "zping", "--endpoint", endpoint,
                               "--count", str(count), "--watch", f"echo={pong.pid}"],
                              capture_output=True, text=True, timeout=120)
        return json.loads(ping.stdout.strip().splitlines()[-1])
    finally:
        pong.stdin.close()
        pong.wait(10)


def flood(pair: Pair, seconds: float, n: int, pace: float) -> dict:
    topic = f"/zb_image_{n}"
    pub = pair.a.role("flood_pub", "--topic", topic, "--seconds", str(seconds), "--pace", str(pace))
    sub = pair.b.role("flood_sub", "--topic", topic, "--seconds", str(seconds),
                      "--watch", pair.watch(pub=pub.pid))
    try:
        return _result(sub)
    finally:
        _stop(pub)
        _stop(sub)


def zenoh_flood_floor(seconds: float, pace: float) -> dict:
    endpoint = f"tcp/127.0.0.1:{_free_port()}"
    # the publisher listens and puts from the start (to no one at first), so that the
    # subscriber, connecting, knows the pid to watch
    pub = subprocess.Popen([PYTHON, __file__, "--role", "zflood_pub", "--endpoint", endpoint,
                            "--seconds", str(seconds), "--pace", str(pace)], stdout=subprocess.DEVNULL,
                           start_new_session=True)
    sub = subprocess.Popen([PYTHON, __file__, "--role", "zflood_sub", "--endpoint", endpoint,
                            "--seconds", str(seconds), "--watch", f"pub={pub.pid}"],
                           stdout=subprocess.PIPE, text=True, start_new_session=True)
    try:
        return _result(sub)
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


MEASURES = ("rtt", "hd", "discovery", "loss")


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--role", choices=sorted(ROLES))
    parser.add_argument("--ping", default="/zb_ping")
    parser.add_argument("--pong", default="/zb_pong")
    parser.add_argument("--topic", default="/zb_image")
    parser.add_argument("--endpoint", default="")
    parser.add_argument("--watch", default="", help=argparse.SUPPRESS)
    parser.add_argument("--count", type=int, default=2000,
                        help="round trips per round (default 2000)")
    parser.add_argument("--seconds", type=float, default=3.0,
                        help="seconds of 1080p frames per round (default 3)")
    parser.add_argument("--rounds", type=int, default=3)
    parser.add_argument("--pace", type=float, default=0.0, metavar="FPS",
                        help="publish the 1080p frames at this rate instead of flooding: the CPU "
                             "per frame below saturation, for comparing versions on a busy machine")
    parser.add_argument("--only", default=",".join(MEASURES),
                        help=f"measures to run, of {','.join(MEASURES)} (default all)")
    parser.add_argument("--baseline", default="", metavar="PY",
                        help="add 'baseline': two more bridges run by this interpreter (another "
                             "checkout's venv), so two versions of the bridge meet in one run")
    args = parser.parse_args(argv)
    if args.role:
        ROLES[args.role](args)
        return 0
    only = set(args.only.split(","))
    if only - set(MEASURES):
        parser.error(f"--only: unknown {','.join(sorted(only - set(MEASURES)))}")
    signal.signal(signal.SIGTERM, lambda *_: sys.exit(1))  # stopped: the finally below cleans up
    home = tempfile.mkdtemp(prefix="zenoh-bench-")
    pairs: dict = {}
    results: dict = {}
    try:
        a, b = Site("a", home), Site("b", home)
        pairs["TCPROS"] = Pair(a, None)
        pairs["2 bridges"] = Pair(a, b)
        if args.baseline:
            pairs["baseline"] = Pair(Site("a0", home, args.baseline), Site("b0", home, args.baseline))
        for pair in pairs.values():
            pair.start()
        bridged = [w for w in pairs if w != "TCPROS"]
        for r in range(args.rounds):
            if "rtt" in only:
                for where, pair in pairs.items():
                    results.setdefault(("rtt", where), []).append(rtt(pair, args.count, r))
                results.setdefault(("rtt", "Zenoh floor"), []).append(zenoh_floor(args.count))
            if "hd" in only:
                for where, pair in pairs.items():
                    results.setdefault(("hd", where), []).append(flood(pair, args.seconds, r, args.pace))
                results.setdefault(("hd", "Zenoh floor"), []).append(zenoh_flood_floor(args.seconds, args.pace))
            for where in bridged:
                pair = pairs[where]
                if "discovery" in only:
                    results.setdefault(("discovery", where), []).append(
                        {"value": discovery(pair.a, pair.b, r)})
                if "loss" in only:
                    results.setdefault(("loss", where), []).append(
                        {"value": loss(pair.a, pair.b, r)})
            print(f"round {r + 1}/{args.rounds} done", file=sys.stderr, flush=True)
    finally:
        for pair in pairs.values():
            pair.stop()
    report(args, results, list(pairs) + ["Zenoh floor"])
    return 0


def report(args, results: dict, columns: list) -> None:
    rows = [("small-message round trip (us)", "rtt", "median_us", "<= 300"),
            ("1920x1080 rgb8 frames/s received", "hd", "rate", ">= 300"),
            ("new remote topic listed after (s)", "discovery", "value", "<= 1.5"),
            ("remote loss noticed after (s)", "loss", "value", "<= 3.5")]
    load = os.getloadavg()[0]
    print(f"\nminros zenoh vs TCPROS, median of {args.rounds} interleaved rounds "
          f"(python {sys.version.split()[0]}, {os.cpu_count()} CPUs, load average {load:.1f})\n")
    print(f"{'measure':36}" + "".join(f"{c:>13}" for c in columns) + f"{'target':>8}")
    for title, kind, field, target in rows:
        if not any((kind, c) in results for c in columns):
            continue
        cells = []
        for where in columns:
            values = [r[field] for r in results.get((kind, where), [])]
            cells.append(f"{statistics.median(values):.3g}" if values else "-")
        print(f"{title:36}" + "".join(f"{c:>13}" for c in cells) + f"{target:>8}")
    # CPU per message: what each process spends, which the load does not change much
    for kind, unit in (("rtt", "round trip (us)"), ("hd", "frame (ms)")):
        labels: list = []
        for where in columns:
            for r in results.get((kind, where), []):
                labels += [k for k in r.get("cpu_ms", {}) if k not in labels]
        if not labels:
            continue
        print(f"\nCPU per {unit}, by process")
        for label in labels + ["total"]:
            cells = []
            for where in columns:
                values = [sum(r["cpu_ms"].values()) if label == "total" else r["cpu_ms"][label]
                          for r in results.get((kind, where), []) if label in r.get("cpu_ms", {})
                          or (label == "total" and r.get("cpu_ms"))]
                scale = 1e3 if kind == "rtt" else 1.0
                cells.append(f"{statistics.median(values) * scale:.3g}" if values else "-")
            print(f"{'  ' + label:36}" + "".join(f"{c:>13}" for c in cells))


if __name__ == "__main__":
    sys.exit(main())
