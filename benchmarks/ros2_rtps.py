#!/usr/bin/env python3
"""minros's DDS (minros.ros2) beside rclpy's, in one run: small-message round trip and
1920x1080 rgb8 frames/s, with the CPU each process spends per message.

    sudo .venv/bin/python benchmarks/ros2_rtps.py [--rounds 3] [--count 500] [--frames 40]

Everything runs in one network namespace with only loopback (made and deleted here, as
root). Contenders, interleaved round by round (the table shows the medians of the rounds):

* rclpy -> rclpy: two rclpy Jazzy processes on Fast DDS as installed, which moves data
  between processes of one host through shared memory; and again with Fast DDS on UDP only
  (``FASTDDS_BUILTIN_TRANSPORTS=UDPv4``), the wire minros speaks;
* minros -> rclpy, rclpy -> minros, minros -> minros: one side (or both) a minros process
  (``minros.ros2.rmw``: serialized CDR bytes in and out, no message objects).

Round trip: ``std_msgs/UInt8MultiArray`` of 100 bytes, the echo side republishing from its
callback (rclpy republishes the message object it got; minros the bytes), reliable,
keep-last 10, median of ``--count`` after a warm-up. Frames: ``sensor_msgs/Image``
1920x1080 rgb8 (6,220,800 bytes of data) published back to back, at most two unanswered (the
receiver answers each frame with a small message), reliable, keep-last 10; frames/s over
``--frames``. rclpy builds and deserializes message objects (its users' cost); minros's side
does not (the bridge adds its conversion on top). CPU: user + system seconds of each process
over the measured part, per round trip or per frame.

This file is also the worker: ``--role ...`` runs one side (under minros's interpreter or
the pip ROS 2's) and answers JSON lines.
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


def cpu() -> float:
    usage = resource.getrusage(resource.RUSAGE_SELF)
    return usage.ru_utime + usage.ru_stime


def emit(obj: dict) -> None:
    print(json.dumps(obj), flush=True)


# -- the two stacks behind one small interface ----------------------------------------------

class MinrosSide:
    def __init__(self, name: str) -> None:
        from minros.ros2.rmw import Context

        self.ctx = Context(0)
        self.node = self.ctx.create_node(name)

    def publisher(self, topic: str, kind: str):
        from minros.ros2.rmw import QoSProfile

        type_name = "sensor_msgs/msg/Image" if kind == "image" else "std_msgs/msg/UInt8MultiArray"
        pub = self.node.create_publisher(topic, type_name, QoSProfile(depth=10))
        return pub, pub.publish, pub.get_subscription_count

    def subscription(self, topic: str, kind: str, callback):
        from minros.ros2.rmw import QoSProfile

        type_name = "sensor_msgs/msg/Image" if kind == "image" else "std_msgs/msg/UInt8MultiArray"
        sub = self.node.create_subscription(topic, type_name, lambda p, i: callback(p),
                                            QoSProfile(depth=10))
        return sub, sub.get_publisher_count

    @staticmethod
    def small(index: int) -> bytes:
        return (b"\x00\x01\x00\x00" + (0).to_bytes(4, "little") * 2
                + SMALL.to_bytes(4, "little") + index.to_bytes(4, "little") + bytes(SMALL - 4))

    @staticmethod
    def image() -> bytes:
        sys.path.insert(0, os.path.join(REPO, "tests"))
        from ros2_support import cdr_image

        return cdr_image(WIDTH, HEIGHT, bytes(WIDTH * HEIGHT * 3))

    def close(self) -> None:
        self.ctx.shutdown()


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

    def _type(self, kind: str):
        from sensor_msgs.msg import Image
        from std_msgs.msg import UInt8MultiArray

        return Image if kind == "image" else UInt8MultiArray

    def publisher(self, topic: str, kind: str):
        pub = self.node.create_publisher(self._type(kind), topic, 10)
        return pub, pub.publish, pub.get_subscription_count

    def subscription(self, topic: str, kind: str, callback):
        sub = self.node.create_subscription(self._type(kind), topic, callback, 10)
        return sub, sub.get_publisher_count

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
        self.executor.shutdown(timeout_sec=1)
        self.rclpy.try_shutdown()


def worker(args: argparse.Namespace) -> None:
    tune = os.environ.get("MINROS_BENCH_PACING")  # "fragments,gap_s": to measure the pacing
    if tune and args.stack == "minros":
        from minros.ros2.rtps import guid, participant, writer

        fragments, gap = tune.split(",")
        participant.FIRST_BURST[guid.VENDOR_FASTDDS] = int(fragments) * writer.FRAGMENT_SIZE
        defaults = list(writer.Writer.__init__.__kwdefaults__.items())
        writer.Writer.__init__.__kwdefaults__.update(dict(defaults, gap=float(gap)))
    side = MinrosSide(args.role) if args.stack == "minros" else RclpySide(args.role)
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
    deadline = time.time() + 30
    while (subs() < 1 or pubs() < 1) and time.time() < deadline:
        time.sleep(0.01)
    emit({"ready": subs() >= 1 and pubs() >= 1})
    for line in sys.stdin:
        command = line.strip()
        if command == "cpu":
            emit({"cpu": cpu()})
        elif command == "go" and args.role == "ping":
            messages = [side.small(i) for i in range(args.count + 50)]
            for msg in messages[:50]:  # warm up; a lost early sample only costs a timeout
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
            for _ in range(2):  # warm up
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
            elapsed = time.perf_counter() - t0
            stats = {}
            if args.stack == "minros":  # the writer's flow control, for the notes
                machine = pub.writer.machine
                stats = {"resent": machine.fragments_resent,
                         "bursts": [p.burst for p in machine.proxies.values()],
                         "cuts": [p.cuts for p in machine.proxies.values()],
                         "rounds": [p.rounds for p in machine.proxies.values()]}
            emit({"frames": answers[0] - done0, "elapsed": elapsed, "cpu": cpu() - c0, **stats})
        elif command == "quit":
            break
    side.close()


# -- the orchestration -------------------------------------------------------------------------

def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--rounds", type=int, default=3)
    parser.add_argument("--count", type=int, default=500, help="round trips per contender")
    parser.add_argument("--frames", type=int, default=40, help="1080p frames per contender")
    parser.add_argument("--role")
    parser.add_argument("--stack")
    parser.add_argument("--topic", default="bench")
    args = parser.parse_args()
    if args.role:
        worker(args)
        return
    if os.geteuid() != 0:
        raise SystemExit("error: the benchmark runs DDS in a network namespace of its own: run "
                         "it as root (sudo .venv/bin/python benchmarks/ros2_rtps.py)")
    sys.path.insert(0, os.path.join(REPO, "tests"))
    from ros2_support import Netns, ros2_env, ros2_python

    jazzy = ros2_python("jazzy")
    if not jazzy.exists():
        raise SystemExit(f"error: the pip ROS 2 is not installed ({jazzy}): "
                         "bash scripts/install-ros2-reference.sh")
    pythons = {"minros": sys.executable, "rclpy": str(jazzy)}
    udp = {"FASTDDS_BUILTIN_TRANSPORTS": "UDPv4"}
    contenders = [
        ("rclpy -> rclpy (Fast DDS: shared memory)", "rclpy", "rclpy", {}),
        ("rclpy -> rclpy (Fast DDS: UDP only)", "rclpy", "rclpy", udp),
        ("minros -> rclpy", "minros", "rclpy", {}),
        ("rclpy -> minros", "rclpy", "minros", {}),
        ("minros -> minros", "minros", "minros", {}),
    ]
    import tempfile
    from pathlib import Path

    tmp = Path(tempfile.mkdtemp(prefix="ros2-bench-"))
    ns = Netns()
    results: dict = {name: {"rtt": [], "rtt_cpu": [], "fps": [], "frame_cpu": []}
                     for name, *_ in contenders}
    try:
        for round_ in range(args.rounds):
            for test in ("rtt", "frames"):
                for i, (name, first, second, extra) in enumerate(contenders):
                    topic = f"b{round_}{test[0]}{i}"
                    roles = ("ping", "pong") if test == "rtt" else ("source", "sink")
                    out = pair(ns, tmp, pythons, (first, roles[0]), (second, roles[1]), topic,
                               args, extra, ros2_env)
                    r = results[name]
                    if out is None:
                        continue
                    print(f"  {name}: {test} " + (
                        f"{statistics.median(out['rtts']) * 1000:.3f} ms" if test == "rtt" else
                        f"{out['frames'] / out['elapsed']:.1f} frames/s "
                        f"{ {k: out[k] for k in ('resent', 'bursts', 'cuts', 'rounds') if k in out} }"),
                        file=sys.stderr,
                        flush=True)
                    if test == "rtt":
                        r["rtt"].append(statistics.median(out["rtts"]) * 1000)
                        r["rtt_cpu"].append(tuple(x * 1000 for x in out["cpu_per"]))
                    else:
                        r["fps"].append(out["frames"] / out["elapsed"])
                        r["frame_cpu"].append(tuple(x * 1000 for x in out["cpu_per"]))
                print(f"round {round_ + 1}/{args.rounds} {test} done", file=sys.stderr,
                      flush=True)
    finally:
        ns.delete()
    print(f"\nROS 2 over DDS, one network namespace (loopback), {args.rounds} rounds, medians; "
          f"{args.count} round trips of a {SMALL}-byte UInt8MultiArray, {args.frames} frames of "
          f"1920x1080 rgb8 per round")
    print(f"{'contender':42} {'round trip':>11} {'CPU/rt':>15} {'1080p':>9} {'CPU/frame':>17}")
    print(f"{'':42} {'ms':>11} {'ms (tx+rx)':>15} {'frames/s':>9} {'ms (tx+rx)':>17}")
    for name, *_ in contenders:
        r = results[name]

        def med(xs: list) -> float:
            return statistics.median(xs) if xs else float("nan")
        rtt_cpu = med([a for a, _ in r["rtt_cpu"]]), med([b for _, b in r["rtt_cpu"]])
        frame_cpu = med([a for a, _ in r["frame_cpu"]]), med([b for _, b in r["frame_cpu"]])
        print(f"{name:42} {med(r['rtt']):11.3f} {rtt_cpu[0]:7.3f}+{rtt_cpu[1]:<7.3f} "
              f"{med(r['fps']):9.1f} {frame_cpu[0]:8.2f}+{frame_cpu[1]:<8.2f}")


def pair(ns, tmp, pythons, initiator, responder, topic, args, extra, ros2_env):
    """Run one measurement: the responder, then the initiator; its result with the CPU of
    both per message ((initiator, responder) seconds)."""
    procs = {}
    try:
        for stack, role in (responder, initiator):
            env = ros2_env(tmp, extra) if stack == "rclpy" else dict(os.environ, **extra)
            argv = [pythons[stack], os.path.abspath(__file__), "--role", role, "--stack", stack,
                    "--topic", topic, "--count", str(args.count), "--frames", str(args.frames)]
            # (rclpy prints "terminate called without an active exception" at exit: quiet)
            procs[role] = subprocess.Popen(ns.argv(argv), stdin=subprocess.PIPE,
                                           stdout=subprocess.PIPE, stderr=subprocess.DEVNULL,
                                           text=True, env=env, bufsize=1)
        for role, proc in procs.items():
            hello = json.loads(proc.stdout.readline())
            if not hello.get("ready"):
                print(f"{topic}: {role} did not match", file=sys.stderr)
                return None
        go_role = initiator[1]
        other = responder[1]

        def ask(role: str, command: str) -> dict:
            procs[role].stdin.write(command + "\n")
            procs[role].stdin.flush()
            return json.loads(procs[role].stdout.readline())
        before = ask(other, "cpu")["cpu"]
        out = ask(go_role, "go")
        after = ask(other, "cpu")["cpu"]
        n = len(out["rtts"]) if "rtts" in out else out["frames"]
        if not n:
            return None
        out["cpu_per"] = (out["cpu"] / n, (after - before) / n)
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
