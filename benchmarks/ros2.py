#!/usr/bin/env python3
"""The ROS 1 <-> ROS 2 bridge (``minros ros2``) beside ROS 2's own floor and ROS 1's, in one
run: small-message round trip and 1920x1080 rgb8 frames/s, with the CPU of every process.

    sudo .venv/bin/python benchmarks/ros2.py [--rounds 3] [--count 500] [--frames 40]

Everything runs in one network namespace with only loopback (made and deleted here, as
root): a master (minros core), one bridge (``minros ros2``, dynamic, as the user runs it),
and a pair of processes per measurement. Contenders, interleaved round by round (the table
shows the medians of the rounds):

* rclpy -> rclpy: two rclpy Jazzy processes on Fast DDS as installed (shared memory between
  processes of one host), and on UDP only (``FASTDDS_BUILTIN_TRANSPORTS=UDPv4``, the wire the
  bridge speaks): ROS 2's own floor;
* ROS 1 <-> bridge <-> rclpy: a ROS 1 process (minros, or Debian's rospy) and an rclpy one,
  each way: the first named starts the round trips and sends the frames;
* TCPROS: minros -> minros and Debian's rospy -> rospy, no bridge: ROS 1's own figure.

Round trip: ``std_msgs/UInt8MultiArray`` of 100 bytes, the echo side republishing the message
it got from its callback, median of ``--count`` after a warm-up. Frames: ``sensor_msgs/Image``
1920x1080 rgb8 (6,220,800 bytes) published back to back, at most two unanswered (the receiver
answers each frame with a small message), frames/s over ``--frames``. The ROS 1 and rclpy
sides use their message classes (their users' cost); the bridge converts bytes. Reliable,
depth/queue 10 everywhere (the bridge's defaults). CPU: user + system seconds of each process
(the two ends and, through the bridge, the bridge) over the measured part, per round trip or
per frame.

This file is also the worker: ``--role ...`` runs one side (under minros's interpreter,
Debian's, or the pip ROS 2's) and answers JSON lines.
"""

from __future__ import annotations

import argparse
import json
import os
import resource
import statistics
import subprocess
import sys
import threading
import time

HERE = os.path.dirname(os.path.abspath(__file__))
REPO = os.path.dirname(HERE)
WIDTH, HEIGHT = 1920, 1080
SMALL = 100
MASTER_PORT = 11311
REFERENCE_PYTHON = "/usr/bin/python3"


def cpu() -> float:
    usage = resource.getrusage(resource.RUSAGE_SELF)
    return usage.ru_utime + usage.ru_stime


def emit(obj: dict) -> None:
    print(json.dumps(obj), flush=True)


# -- the sides behind one small interface --------------------------------------------------------

class Ros1Side:
    """rospy's API: minros's stand-in or Debian's rospy, whichever interpreter runs this."""

    def __init__(self, name: str) -> None:
        import rospy

        self.rospy = rospy
        rospy.init_node(name, anonymous=True, disable_signals=True)

    @staticmethod
    def _type(kind: str):
        from sensor_msgs.msg import Image
        from std_msgs.msg import UInt8MultiArray

        return Image if kind == "image" else UInt8MultiArray

    def publisher(self, topic: str, kind: str):
        pub = self.rospy.Publisher(topic, self._type(kind), queue_size=10, tcp_nodelay=True)
        return pub, pub.publish, pub.get_num_connections

    def subscription(self, topic: str, kind: str, callback):
        sub = self.rospy.Subscriber(topic, self._type(kind), callback, queue_size=10,
                                    tcp_nodelay=True)
        return sub, sub.get_num_connections

    @staticmethod
    def small(index: int):
        from std_msgs.msg import UInt8MultiArray

        return UInt8MultiArray(data=index.to_bytes(4, "little") + bytes(SMALL - 4))

    @staticmethod
    def image():
        from sensor_msgs.msg import Image

        msg = Image(height=HEIGHT, width=WIDTH, encoding="rgb8", step=WIDTH * 3,
                    data=bytes(WIDTH * HEIGHT * 3))
        msg.header.frame_id = "camera"
        return msg

    def close(self) -> None:
        self.rospy.signal_shutdown("done")


class RclpySide:
    def __init__(self, name: str) -> None:
        import rclpy
        from rclpy.executors import SingleThreadedExecutor
        from rclpy.node import Node

        rclpy.init()
        self.rclpy = rclpy
        self.node = Node(name)
        self.executor = SingleThreadedExecutor()
        self.executor.add_node(self.node)
        threading.Thread(target=self.executor.spin, daemon=True).start()

    @staticmethod
    def _type(kind: str):
        from sensor_msgs.msg import Image
        from std_msgs.msg import UInt8MultiArray

        return Image if kind == "image" else UInt8MultiArray

    def publisher(self, topic: str, kind: str):
        pub = self.node.create_publisher(self._type(kind), topic, 10)
        return pub, pub.publish, pub.get_subscription_count

    def subscription(self, topic: str, kind: str, callback):
        sub = self.node.create_subscription(self._type(kind), topic, callback, 10)
        return sub, sub.get_publisher_count

    small = staticmethod(Ros1Side.small)
    image = staticmethod(Ros1Side.image)

    def close(self) -> None:
        self.executor.shutdown(timeout_sec=1)
        self.rclpy.try_shutdown()


def worker(args: argparse.Namespace) -> None:
    side = RclpySide(args.role) if args.stack == "rclpy" else Ros1Side(args.role)
    got = threading.Event()
    answers = [0]

    def on_answer(msg) -> None:
        answers[0] += 1
        got.set()
    if args.role in ("pong", "sink"):
        pub, publish, subs = side.publisher(args.topic + "_back", "small")
        if args.role == "pong":
            sub, pubs = side.subscription(args.topic, "small", publish)
        else:
            ack = side.small(0)
            sub, pubs = side.subscription(args.topic, "image", lambda msg: publish(ack))
    else:
        kind = "image" if args.role == "source" else "small"
        pub, publish, subs = side.publisher(args.topic, kind)
        sub, pubs = side.subscription(args.topic + "_back", "small", on_answer)
    deadline = time.time() + 60
    while (subs() < 1 or pubs() < 1) and time.time() < deadline:
        time.sleep(0.01)
    emit({"ready": subs() >= 1 and pubs() >= 1})
    for line in sys.stdin:
        command = line.strip()
        if command == "cpu":
            emit({"cpu": cpu()})
        elif command == "go" and args.role == "ping":
            messages = [side.small(i) for i in range(args.count + 50)]
            for msg in messages[:50]:  # warm up; a lost early message only costs a timeout
                got.clear()
                publish(msg)
                got.wait(1.0)
            rtts = []
            c0 = cpu()
            for msg in messages[50:]:
                got.clear()
                t0 = time.perf_counter()
                publish(msg)
                if not got.wait(5.0):
                    break
                rtts.append(time.perf_counter() - t0)
            emit({"rtts": rtts, "cpu": cpu() - c0})
        elif command == "go" and args.role == "source":
            frame = side.image()
            for _ in range(3):  # warm up
                got.clear()
                publish(frame)
                got.wait(5.0)
            done0 = answers[0]
            sent = 0
            t0 = time.perf_counter()
            c0 = cpu()
            while True:
                acked = answers[0] - done0
                if acked >= args.frames:
                    break
                if sent - acked < 2 and sent < args.frames:
                    publish(frame)
                    sent += 1
                    continue
                got.clear()
                if answers[0] - done0 == acked and not got.wait(10.0):
                    break
            emit({"frames": answers[0] - done0, "elapsed": time.perf_counter() - t0,
                  "cpu": cpu() - c0})
        elif command == "quit":
            break
    side.close()


# -- the orchestration ---------------------------------------------------------------------------

def proc_cpu(pid: int) -> float:
    """User + system seconds of process ``pid`` (all its threads)."""
    with open(f"/proc/{pid}/stat") as f:
        fields = f.read().rsplit(")", 1)[1].split()
    return (int(fields[11]) + int(fields[12])) / os.sysconf("SC_CLK_TCK")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--rounds", type=int, default=3)
    parser.add_argument("--count", type=int, default=500, help="round trips per contender")
    parser.add_argument("--frames", type=int, default=40, help="1080p frames per contender")
    parser.add_argument("--only", default="", help="run contenders whose name has this text")
    parser.add_argument("--role")
    parser.add_argument("--stack")
    parser.add_argument("--topic", default="bench")
    args = parser.parse_args()
    if args.role:
        worker(args)
        return
    if os.geteuid() != 0:
        raise SystemExit("error: the benchmark runs DDS in a network namespace of its own: run "
                         "it as root (sudo .venv/bin/python benchmarks/ros2.py)")
    sys.path.insert(0, os.path.join(REPO, "tests"))
    from ros2_support import Netns, ros2_env, ros2_python

    jazzy = ros2_python("jazzy")
    if not jazzy.exists():
        raise SystemExit(f"error: the pip ROS 2 is not installed ({jazzy}): "
                         "bash scripts/install-ros2-reference.sh")
    rospy = os.path.exists("/usr/lib/python3/dist-packages/rospy")
    pythons = {"minros": sys.executable, "rclpy": str(jazzy), "rospy": REFERENCE_PYTHON}
    udp = {"FASTDDS_BUILTIN_TRANSPORTS": "UDPv4"}
    B = "bridge"
    contenders = [
        ("rclpy -> rclpy (Fast DDS: shared memory)", "rclpy", "rclpy", {}, None),
        ("rclpy -> rclpy (Fast DDS: UDP only)", "rclpy", "rclpy", udp, None),
        ("minros ROS 1 -> bridge -> rclpy", "minros", "rclpy", {}, B),
        ("rclpy -> bridge -> minros ROS 1", "rclpy", "minros", {}, B),
        ("rospy -> bridge -> rclpy", "rospy", "rclpy", {}, B),
        ("rclpy -> bridge -> rospy", "rclpy", "rospy", {}, B),
        ("TCPROS minros -> minros", "minros", "minros", {}, None),
        ("TCPROS rospy -> rospy", "rospy", "rospy", {}, None),
    ]
    contenders = [c for c in contenders if args.only in c[0]
                  and (rospy or "rospy" not in (c[1], c[2]))]
    import tempfile
    from pathlib import Path

    tmp = Path(tempfile.mkdtemp(prefix="ros2-bridge-bench-"))
    ns = Netns()
    home = tmp / "ros_home"
    home.mkdir()
    ros1_env = {k: v for k, v in os.environ.items() if not k.startswith("ROS_")}
    ros1_env.pop("PYTHONPATH", None)
    ros1_env.update({"ROS_MASTER_URI": f"http://localhost:{MASTER_PORT}",
                     "ROS_HOSTNAME": "localhost", "ROS_HOME": str(home),
                     "ROS_LOG_DIR": str(home / "log"), "PYTHONUNBUFFERED": "1"})
    daemons = []
    results: dict = {name: {"rtt": [], "rtt_cpu": [], "fps": [], "frame_cpu": []}
                     for name, *_ in contenders}
    try:
        master = subprocess.Popen(ns.argv([sys.executable, "-m", "minros", "core", "-p",
                                           str(MASTER_PORT)]), env=ros1_env,
                                  stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
        daemons.append(master)
        for line in master.stdout:
            if "started core service" in line:
                break
        threading.Thread(target=lambda: [None for _ in master.stdout], daemon=True).start()
        bridge = subprocess.Popen(ns.argv([sys.executable, "-m", "minros", "ros2",
                                           "--distro", "jazzy"]), env=ros1_env,
                                  stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
        daemons.append(bridge)
        line = bridge.stdout.readline()
        if "bridging the ROS master" not in line:
            raise SystemExit(f"error: the bridge did not start: {line}")
        threading.Thread(target=lambda: [None for _ in bridge.stdout], daemon=True).start()
        for round_ in range(args.rounds):
            for test in ("rtt", "frames"):
                for i, (name, first, second, extra, via) in enumerate(contenders):
                    topic = f"/b{round_}{test[0]}{i}"
                    roles = ("ping", "pong") if test == "rtt" else ("source", "sink")
                    out = pair(ns, tmp, pythons, (first, roles[0]), (second, roles[1]), topic,
                               args, extra, ros2_env, ros1_env,
                               bridge.pid if via else None)
                    r = results[name]
                    if out is None:
                        continue
                    print(f"  {name}: {test} " + (
                        f"{statistics.median(out['rtts']) * 1000:.3f} ms" if test == "rtt" else
                        f"{out['frames'] / out['elapsed']:.1f} frames/s"),
                        file=sys.stderr, flush=True)
                    if test == "rtt":
                        r["rtt"].append(statistics.median(out["rtts"]) * 1000)
                        r["rtt_cpu"].append(tuple(x * 1000 for x in out["cpu_per"]))
                    else:
                        r["fps"].append(out["frames"] / out["elapsed"])
                        r["frame_cpu"].append(tuple(x * 1000 for x in out["cpu_per"]))
                print(f"round {round_ + 1}/{args.rounds} {test} done", file=sys.stderr,
                      flush=True)
    finally:
        for proc in reversed(daemons):
            proc.terminate()
            try:
                proc.wait(10)
            except subprocess.TimeoutExpired:
                proc.kill()
        ns.delete()
    with open("/proc/loadavg") as f:
        load = " ".join(f.read().split()[:3])
    print(f"\nROS 1 <-> ROS 2 through minros ros2, beside rclpy and TCPROS; one network namespace "
          f"(loopback), {args.rounds} rounds, medians; {args.count} round trips of a "
          f"{SMALL}-byte UInt8MultiArray, {args.frames} frames of 1920x1080 rgb8 per round; "
          f"load average at the end {load}")
    print(f"{'contender':42} {'round trip':>10} {'CPU/round trip':>22} {'1080p':>9} "
          f"{'CPU/frame':>24}")
    print(f"{'':42} {'ms':>10} {'ms (a+bridge+b)':>22} {'frames/s':>9} {'ms (a+bridge+b)':>24}")
    for name, *_ in contenders:
        r = results[name]

        def med(xs: list) -> float:
            return statistics.median(xs) if xs else float("nan")

        def cpu_text(rows: list, width: int) -> str:
            parts = [med([row[k] for row in rows]) for k in range(3)] if rows else [float("nan")] * 3
            total = sum(p for p in parts if p == p)
            body = f"{parts[0]:.2f}+{parts[1]:.2f}+{parts[2]:.2f}" if parts[1] else \
                f"{parts[0]:.2f}+{parts[2]:.2f}"
            return f"{total:6.2f} ({body})".rjust(width)
        print(f"{name:42} {med(r['rtt']):10.3f} {cpu_text(r['rtt_cpu'], 22)} "
              f"{med(r['fps']):9.1f} {cpu_text(r['frame_cpu'], 24)}")


def pair(ns, tmp, pythons, initiator, responder, topic, args, extra, ros2_env, ros1_env,
         bridge_pid):
    """Run one measurement: the responder, then the initiator; its result with the CPU per
    message of (initiator, bridge, responder), in seconds."""
    procs = {}
    try:
        for stack, role in (responder, initiator):
            if stack == "rclpy":
                env = ros2_env(tmp, extra)
            else:
                env = dict(ros1_env)
                if stack == "rospy":
                    env["PATH"] = "/usr/bin:/bin"
                    env.pop("VIRTUAL_ENV", None)
            argv = [pythons[stack], os.path.abspath(__file__), "--role", role, "--stack", stack,
                    "--topic", topic, "--count", str(args.count), "--frames", str(args.frames)]
            # (rclpy prints "terminate called without an active exception" at exit)
            procs[role] = subprocess.Popen(ns.argv(argv), stdin=subprocess.PIPE,
                                           stdout=subprocess.PIPE,
                                           stderr=open(tmp / f"{topic[1:]}-{role}.log", "w"),
                                           text=True, env=env, bufsize=1)
        for role, proc in procs.items():
            hello = None
            for line in proc.stdout:  # (a ROS 1 node may print a log line first)
                if line.startswith("{"):
                    hello = json.loads(line)
                    break
            if not hello or not hello.get("ready"):
                print(f"{topic}: {role} did not connect", file=sys.stderr)
                return None
        go_role = initiator[1]
        other = responder[1]

        def ask(role: str, command: str) -> dict:
            procs[role].stdin.write(command + "\n")
            procs[role].stdin.flush()
            for line in procs[role].stdout:
                if line.startswith("{"):
                    return json.loads(line)
            raise RuntimeError(f"{role} exited")
        before = ask(other, "cpu")["cpu"]
        bridge0 = proc_cpu(bridge_pid) if bridge_pid else 0.0
        out = ask(go_role, "go")
        bridge1 = proc_cpu(bridge_pid) if bridge_pid else 0.0
        after = ask(other, "cpu")["cpu"]
        n = len(out["rtts"]) if "rtts" in out else out["frames"]
        if not n:
            return None
        out["cpu_per"] = (out["cpu"] / n, (bridge1 - bridge0) / n, (after - before) / n)
        return out
    finally:
        for proc in procs.values():
            try:
                proc.stdin.write("quit\n")
                proc.stdin.flush()
                proc.wait(10)
            except (OSError, subprocess.TimeoutExpired):
                proc.kill()


if __name__ == "__main__":
    main()
