#!/usr/bin/env python3
"""rosbag benchmark: minros's recorder, player and Bag API beside Debian's (C++ record and
play, Python Bag) in the same run, on one Debian rosmaster.

    .venv/bin/python benchmarks/bag.py [--seconds 20] [--rounds 3] [--gigabytes 1.0]

* record: one minros publisher sends a 1920x1080 bgr8 sensor_msgs/Image at 30 Hz and a
  std_msgs/String at 1 kHz for ``--seconds``; each recorder (default options, -b 256 MB)
  records both topics into a bag on /tmp; messages lost = sent - in the bag, per topic.
* play: a bag of 1000 String messages 10 ms apart (with up to 3 ms of jitter) is played at
  -r 1 by each player to one minros subscriber; the error of message i is
  (receive_i - receive_0) - (bag_i - bag_0); median and 99th percentile of |error|.
* read: a bag of ``--gigabytes`` GB (640x480 rgb8 images at 30 Hz and sensor_msgs/Imu at
  1 kHz, the mix of a camera robot) is written to a temporary directory; each Bag API reads
  every message deserialized (``read_messages()``), page cache warm, in a fresh process that
  imported ``rospy`` and ``rosbag`` before the clock starts (Debian's ``import rosbag`` imports
  rospy itself; minros's imports its node stack when the first timestamp is made, 30 ms that
  would otherwise be timed as reading).
* info: ``rosbag info`` on that bag, the whole command (interpreter start included).
* convert: a bag of ``--gigabytes`` GB of 640x480 rgb8 images at 30 Hz and 720-ray
  sensor_msgs/LaserScan at 40 Hz, converted to a ROS 2 recording (rosbag2, MCAP, Jazzy types)
  by ``minros bag convert`` and by ``rosbags-convert --dst-typestore ros2_jazzy``, each the
  whole command (interpreter start included), page cache warm, interleaved; MB/s of the input
  bag. ``--only convert`` runs this part alone (it needs no ROS 1 reference).

The bag files are deleted at the end. This file is also the worker (``--role``), run by the
venv's Python for minros and by /usr/bin/python3 for Debian's rosbag (``import rosbag``
finds the stand-in or the real package).
"""

from __future__ import annotations

import argparse
import json
import os
import random
import shutil
import signal
import statistics
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

# --------------------------------------------------------------------------------- workers


def role_publish(args) -> None:
    """/image (1080p bgr8, 30 Hz) and /small (1 kHz) for args.seconds once both are heard."""
    import rospy
    from sensor_msgs.msg import Image
    from std_msgs.msg import String

    rospy.init_node("bench_pub", anonymous=True)
    image_pub = rospy.Publisher("/image", Image, queue_size=10)
    small_pub = rospy.Publisher("/small", String, queue_size=1000)
    while (image_pub.get_num_connections() == 0 or small_pub.get_num_connections() == 0) \
            and not rospy.is_shutdown():
        time.sleep(0.01)
    time.sleep(1.0)  # the recorder has opened its bag
    print(json.dumps({"ready": True}), flush=True)
    img = Image(height=1080, width=1920, encoding="bgr8", step=1920 * 3,
                data=bytes(1920 * 1080 * 3))
    end = time.monotonic() + args.seconds
    sent = {"image": 0, "small": 0}

    def images() -> None:
        rate = rospy.Rate(30)
        while time.monotonic() < end:
            image_pub.publish(img)
            sent["image"] += 1
            rate.sleep()

    thread = threading.Thread(target=images)
    thread.start()
    rate = rospy.Rate(1000)
    while time.monotonic() < end:
        small_pub.publish(String("x" * 40))
        sent["small"] += 1
        rate.sleep()
    thread.join()
    print(json.dumps(sent), flush=True)


def role_listen(args) -> None:
    """Receive args.count messages on /timed; print their receive times."""
    import rospy
    from std_msgs.msg import String

    times = []
    done = threading.Event()

    def on_msg(_msg) -> None:
        times.append(time.time())
        if len(times) >= args.count:
            done.set()

    rospy.init_node("bench_listen", anonymous=True)
    rospy.Subscriber("/timed", String, on_msg, tcp_nodelay=True)
    print(json.dumps({"ready": True}), flush=True)
    done.wait(args.seconds)
    print(json.dumps({"times": times}), flush=True)


def role_read(args) -> None:
    import rosbag
    import rospy  # noqa: F401  (see the module docstring: imports are not reading)

    start = time.perf_counter()
    n = 0
    size = 0
    with rosbag.Bag(args.path) as bag:
        for _topic, msg, _t in bag.read_messages():
            n += 1
            size += len(getattr(msg, "data", b""))
    print(json.dumps({"seconds": time.perf_counter() - start, "count": n, "bytes": size}), flush=True)


# --------------------------------------------------------------------------------- helpers


def make_play_bag(path: str) -> list:
    import minros
    from minros.bag import Bag
    from std_msgs.msg import String

    random.seed(7)
    stamps = []
    with Bag(path, "w") as bag:
        for i in range(1000):
            t = 1_000_000_000_000 + i * 10_000_000 + random.randrange(0, 3_000_000)
            stamps.append(t)
            bag.write("/timed", String(f"m{i}"), minros.Time(t // 10**9, t % 10**9))
    return stamps


def make_big_bag(path: str, gigabytes: float) -> int:
    """Raw writes of one serialized Image and one Imu, at camera/IMU rates, up to the size."""
    import io

    import minros
    from minros.bag import Bag
    from sensor_msgs.msg import Image, Imu

    img = Image(height=480, width=640, encoding="rgb8", step=640 * 3, data=bytes(640 * 480 * 3))
    imu = Imu()
    imu.header.frame_id = "imu"
    blobs = {}
    for name, msg in (("image", img), ("imu", imu)):
        buff = io.BytesIO()
        msg.serialize(buff)
        blobs[name] = (msg._type, buff.getvalue(), msg._md5sum, type(msg))
    target = int(gigabytes * 1e9)
    written = 0
    t = 1_700_000_000 * 10**9
    i = 0
    with Bag(path, "w") as bag:
        while written < target:
            stamp = minros.Time(t // 10**9, t % 10**9)
            bag.write("/imu", blobs["imu"], stamp, raw=True)
            written += len(blobs["imu"][1])
            if i % 33 == 0:
                bag.write("/camera/image", blobs["image"], stamp, raw=True)
                written += len(blobs["image"][1])
            i += 1
            t += 1_000_000
    return os.path.getsize(path)


def make_convert_bag(path: str, gigabytes: float) -> int:
    """Raw writes of one serialized 640x480 image and one 720-ray scan at 30 and 40 Hz."""
    import io
    import math

    import minros
    from minros.bag import Bag
    from sensor_msgs.msg import Image, LaserScan

    img = Image(height=480, width=640, encoding="rgb8", step=640 * 3,
                data=bytes(range(256)) * (640 * 480 * 3 // 256))
    img.header.frame_id = "camera"
    scan = LaserScan(angle_min=-math.pi, angle_max=math.pi, angle_increment=2 * math.pi / 720,
                     range_min=0.1, range_max=30.0, ranges=[1.0 + i / 100 for i in range(720)],
                     intensities=[100.0] * 720)
    scan.header.frame_id = "laser"
    blobs = {}
    for name, msg in (("image", img), ("scan", scan)):
        buff = io.BytesIO()
        msg.serialize(buff)
        blobs[name] = (msg._type, buff.getvalue(), msg._md5sum, type(msg))
    target = int(gigabytes * 1e9)
    written = 0
    t = 1_700_000_000 * 10**9
    tick = 0
    with Bag(path, "w") as bag:
        while written < target:  # a 120 Hz tick: images every 4th, scans every 3rd
            stamp = minros.Time(t // 10**9, t % 10**9)
            if tick % 4 == 0:
                bag.write("/camera/image_raw", blobs["image"], stamp, raw=True)
                written += len(blobs["image"][1])
            if tick % 3 == 0:
                bag.write("/scan", blobs["scan"], stamp, raw=True)
                written += len(blobs["scan"][1])
            tick += 1
            t += 1_000_000_000 // 120
    return os.path.getsize(path)


def convert_once(who: str, src: str, dst: str) -> float:
    """Seconds of one whole conversion command (the output removed afterwards)."""
    if who == "minros":
        cmd = [VENV_PYTHON, "-m", "minros", "bag", "convert", "-q", src, dst]
    else:
        cmd = [os.path.join(os.path.dirname(VENV_PYTHON), "rosbags-convert"), "--src", src,
               "--dst", dst, "--dst-storage", "mcap", "--dst-typestore", "ros2_jazzy"]
    start = time.perf_counter()
    result = subprocess.run(cmd, capture_output=True, text=True, timeout=1800)
    elapsed = time.perf_counter() - start
    if result.returncode != 0:
        sys.exit(f"benchmarks/bag.py: {who} convert failed: {result.stderr[-2000:]}")
    shutil.rmtree(dst, ignore_errors=True)
    return elapsed


def convert_rows(tmp: str, gigabytes: float, rounds: int) -> list:
    src = os.path.join(tmp, "convert.bag")
    size = make_convert_bag(src, gigabytes)
    subprocess.run(["cat", src], stdout=subprocess.DEVNULL, check=True)  # warm the page cache
    who = ("minros", "rosbags-convert")
    times = {w: [] for w in who}
    for _ in range(rounds):
        for w in who:
            times[w].append(convert_once(w, src, os.path.join(tmp, "converted")))
    os.remove(src)
    rate = {w: size / 1e6 / statistics.median(times[w]) for w in who}
    secs = {w: statistics.median(times[w]) for w in who}
    return [(f"convert a {size / 1e9:.2f} GB bag (images, scans) to ROS 2 MCAP: MB/s",
             f"{rate['minros']:.0f}", f"{rate['rosbags-convert']:.0f}",
             f"{rate['minros'] / rate['rosbags-convert']:.1f}x faster"),
            ("  the same, seconds (whole command)", f"{secs['minros']:.2f}",
             f"{secs['rosbags-convert']:.2f}", "")]


def print_table(header: tuple, rows: list) -> None:
    widths = [max(len(str(row[k])) for row in [header, *rows]) for k in range(4)]
    for row in [header, tuple("-" * w for w in widths), *rows]:
        print(" | ".join(str(c).ljust(w) for c, w in zip(row, widths)))


class Bench:
    def __init__(self, args) -> None:
        self.args = args
        self.tmp = tempfile.mkdtemp(prefix="minros-bag-bench-")
        self.home = os.path.join(self.tmp, "home")
        os.makedirs(os.path.join(self.home, "log"))
        self.port = 20000 + os.getpid() % 20000
        self.master = subprocess.Popen(["/usr/bin/rosmaster", "--core", "-p", str(self.port)],
                                       env=self.env(True), stdout=subprocess.DEVNULL,
                                       stderr=subprocess.DEVNULL, start_new_session=True)
        time.sleep(1.5)

    def env(self, reference: bool) -> dict:
        env = {k: v for k, v in os.environ.items() if not k.startswith("ROS_")}
        env.update(ROS_MASTER_URI=f"http://localhost:{self.port}", ROS_HOSTNAME="localhost",
                   ROS_HOME=self.home, ROS_LOG_DIR=os.path.join(self.home, "log"), PYTHONUNBUFFERED="1")
        if reference:
            env.pop("VIRTUAL_ENV", None)
            env["PATH"] = "/usr/bin:/bin"
        return env

    def worker(self, reference: bool, *argv: str) -> subprocess.Popen:
        python = REFERENCE_PYTHON if reference else VENV_PYTHON
        return subprocess.Popen([python, __file__, *argv], env=self.env(reference), cwd=self.tmp,
                                stdout=subprocess.PIPE, text=True, start_new_session=True)

    @staticmethod
    def stop(proc: subprocess.Popen, timeout: float = 60, group: bool = True) -> None:
        if proc.poll() is None:
            if group:
                os.killpg(proc.pid, signal.SIGINT)
            else:  # rosbag's wrapper hands SIGINT on to the record program itself
                os.kill(proc.pid, signal.SIGINT)
            try:
                proc.wait(timeout)
            except subprocess.TimeoutExpired:
                os.killpg(proc.pid, signal.SIGKILL)
                proc.wait()

    # -- record --------------------------------------------------------------------------

    def record(self, who: str) -> dict:
        path = os.path.join(self.tmp, f"rec-{who}.bag")
        if who == "minros":
            cmd = [VENV_PYTHON, "-m", "minros", "bag", "record", "-O", path, "/image", "/small"]
        else:
            cmd = ["/usr/bin/rosbag", "record", "-O", path, "/image", "/small"]
        recorder = subprocess.Popen(cmd, env=self.env(who != "minros"), cwd=self.tmp,
                                    stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL,
                                    start_new_session=True)
        publisher = self.worker(False, "--role", "publish", "--seconds", str(self.args.seconds))
        try:
            json.loads(publisher.stdout.readline())
            sent = json.loads(publisher.stdout.readline())
            time.sleep(1.0)  # what is still in flight reaches the recorder
        finally:
            self.stop(publisher)
            self.stop(recorder, timeout=300, group=who == "minros")
        from minros.bag import Bag

        # rosbag's wrapper exits at once on SIGINT; its record program is still closing the bag
        deadline = time.monotonic() + 120
        while os.path.exists(path + ".active") and time.monotonic() < deadline:
            time.sleep(0.1)
        if not os.path.exists(path) and os.path.exists(path + ".active"):
            from minros.bag import bag1  # the recorder did not close its bag: count what it holds

            bag1.reindex_in_place(path + ".active")
            os.replace(path + ".active", path)
        with Bag(path) as bag:
            got = {"image": bag.get_message_count("/image"), "small": bag.get_message_count("/small")}
        os.remove(path)
        return {k: (sent[k] - got[k], sent[k]) for k in sent}

    # -- play ----------------------------------------------------------------------------

    def play(self, who: str, stamps: list) -> tuple:
        path = os.path.join(self.tmp, "timed.bag")
        listener = self.worker(False, "--role", "listen", "--count", str(len(stamps)), "--seconds", "60")
        try:
            json.loads(listener.stdout.readline())
            if who == "minros":
                cmd = [VENV_PYTHON, "-m", "minros", "bag", "play", "-q", "-d", "1", path]
            else:
                cmd = ["/usr/bin/rosbag", "play", "-q", "-d", "1", path]
            subprocess.run(cmd, env=self.env(who != "minros"), cwd=self.tmp, capture_output=True,
                           timeout=120)
            times = json.loads(listener.stdout.readline())["times"]
        finally:
            self.stop(listener)
        if len(times) != len(stamps):
            return (float("nan"), float("nan"), len(times))
        errors = sorted(abs((r - times[0]) - (b - stamps[0]) / 1e9) for r, b in zip(times, stamps))
        return (statistics.median(errors) * 1e3, errors[int(len(errors) * 0.99) - 1] * 1e3, len(times))

    # -- read / info ---------------------------------------------------------------------

    def read(self, who: str, path: str) -> float:
        proc = self.worker(who != "minros", "--role", "read", "--path", path)
        out = proc.stdout.read()
        proc.wait()
        return json.loads(out.strip().splitlines()[-1])["seconds"]

    def info(self, who: str, path: str) -> float:
        cmd = ([VENV_PYTHON, "-m", "minros", "bag", "info", path] if who == "minros"
               else ["/usr/bin/rosbag", "info", path])
        start = time.perf_counter()
        result = subprocess.run(cmd, env=self.env(who != "minros"), capture_output=True, timeout=300)
        elapsed = time.perf_counter() - start
        assert result.returncode == 0, result.stderr
        return elapsed

    def close(self) -> None:
        self.stop(self.master)
        shutil.rmtree(self.tmp, ignore_errors=True)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--role", choices=["publish", "listen", "read"])
    parser.add_argument("--seconds", type=float, default=20.0)
    parser.add_argument("--count", type=int, default=0)
    parser.add_argument("--path")
    parser.add_argument("--rounds", type=int, default=3)
    parser.add_argument("--gigabytes", type=float, default=1.0)
    parser.add_argument("--only", choices=["convert"], help="run only this part")
    args = parser.parse_args()
    if args.role:
        {"publish": role_publish, "listen": role_listen, "read": role_read}[args.role](args)
        return
    byte_compile_minros()
    if args.only == "convert":
        tmp = tempfile.mkdtemp(prefix="minros-bag-bench-")
        try:
            rows = convert_rows(tmp, args.gigabytes, args.rounds)
        finally:
            shutil.rmtree(tmp, ignore_errors=True)
        print_table(("measure", "minros", "rosbags-convert", "minros vs rosbags"), rows)
        print(f"\n{args.rounds} rounds (median), contenders interleaved; Python "
              f"{sys.version.split()[0]}; {os.cpu_count()} cores")
        return
    free = shutil.disk_usage(tempfile.gettempdir()).free
    need = args.gigabytes * 1e9 + 2 * 3.8e9 * args.seconds / 20
    if free < need * 1.5:
        sys.exit(f"benchmarks/bag.py: {free / 1e9:.1f} GB free in {tempfile.gettempdir()}, "
                 f"needs about {need * 1.5 / 1e9:.1f} GB: free some, or lower --gigabytes/--seconds")
    bench = Bench(args)
    rows = []
    try:
        who = ("minros", "debian")
        rec = {w: bench.record(w) for w in who}
        for topic, label in (("image", "/image 1080p bgr8 30 Hz"), ("small", "/small 1 kHz")):
            rows.append((f"record {args.seconds:g} s, {label}: lost / sent",
                         *(f"{rec[w][topic][0]} / {rec[w][topic][1]}" for w in who), ""))
        stamps = make_play_bag(os.path.join(bench.tmp, "timed.bag"))
        play = {w: [] for w in who}
        for _ in range(args.rounds):
            for w in who:
                play[w].append(bench.play(w, stamps))
        med = {w: statistics.median(p[0] for p in play[w]) for w in who}
        p99 = {w: statistics.median(p[1] for p in play[w]) for w in who}
        rows.append(("play -r 1: |send time error| median (ms)", f"{med['minros']:.3f}",
                     f"{med['debian']:.3f}", ""))
        rows.append(("play -r 1: |send time error| p99 (ms)", f"{p99['minros']:.3f}",
                     f"{p99['debian']:.3f}", ""))
        big = os.path.join(bench.tmp, "big.bag")
        size = make_big_bag(big, args.gigabytes)
        subprocess.run(["cat", big], stdout=subprocess.DEVNULL, check=True)  # warm the page cache
        reads = {w: [] for w in who}
        infos = {w: [] for w in who}
        for _ in range(args.rounds):
            for w in who:
                reads[w].append(bench.read(w, big))
                infos[w].append(bench.info(w, big))
        r = {w: statistics.median(reads[w]) for w in who}
        i = {w: statistics.median(infos[w]) for w in who}
        rows.append((f"read_messages() of a {size / 1e9:.2f} GB bag (s)", f"{r['minros']:.2f}",
                     f"{r['debian']:.2f}", f"{r['debian'] / r['minros']:.1f}x faster"))
        rows.append(("rosbag info on it (s)", f"{i['minros']:.3f}", f"{i['debian']:.3f}",
                     f"{i['debian'] / i['minros']:.1f}x faster"))
        os.remove(big)
        converted = convert_rows(bench.tmp, args.gigabytes, args.rounds)
    finally:
        bench.close()
    print_table(("measure", "minros", "Debian rosbag", "minros vs Debian"), rows)
    print()
    print_table(("measure", "minros", "rosbags-convert", "minros vs rosbags"), converted)
    print(f"\n{args.rounds} rounds (median) for play/read/info/convert, 1 for record; Python "
          f"{sys.version.split()[0]}; {os.cpu_count()} cores")


if __name__ == "__main__":
    main()
