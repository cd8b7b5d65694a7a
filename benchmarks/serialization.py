"""Serialization speed: minros.msgs beside Debian's genpy, plus a memcpy reference.

    .venv/bin/python benchmarks/serialization.py [--seconds 0.05] [--rounds 7]

For each message it prints messages per second for serialize (into an io.BytesIO, as rospy
does) and deserialize (``cls().deserialize(bytes)``, as rospy does):

* ``minros`` in this interpreter (the venv's),
* ``minros@sys``: minros run by /usr/bin/python3 (``-S``, only minros's src on the path), the
  same interpreter as genpy, so that pair compares the implementations (the venv's pyenv
  Python is built without PGO/LTO and is slower on everything),
* ``genpy``: Debian's generated classes under /usr/bin/python3 (skipped with a note if absent),
* ``memcpy``: copying the same number of bytes once (``bytes(memoryview)``), the floor for a
  deserializer that returns the payload as ``bytes``.

Each figure is the fastest ~2 ms batch (not an average), and rounds alternate between the
processes keeping the best of each, so all columns see the same machine load.
"""

from __future__ import annotations

import argparse
import io
import json
import os
import subprocess
import sys
from typing import Any, Dict, List, Tuple

from minros.msgs import Time, get_message_class
from minros.msgs.testing import GENPY_ORACLE, best_rate, to_plain

REFERENCE_PYTHON = "/usr/bin/python3"


def cases() -> List[Tuple[str, str, Any]]:
    String = get_message_class("std_msgs/String")
    Header = get_message_class("std_msgs/Header")
    PoseStamped = get_message_class("geometry_msgs/PoseStamped")
    Image = get_message_class("sensor_msgs/Image")
    PointCloud2 = get_message_class("sensor_msgs/PointCloud2")
    PointField = get_message_class("sensor_msgs/PointField")

    pose = PoseStamped()
    pose.header.frame_id = "map"
    pose.header.stamp = Time(1700000000, 123)
    pose.pose.position.x, pose.pose.orientation.w = 1.5, 1.0

    def image(width: int, height: int) -> Any:
        return Image(header=Header(seq=1, stamp=Time(5, 6), frame_id="camera"), height=height,
                     width=width, encoding="rgb8", is_bigendian=0, step=width * 3,
                     data=os.urandom(width * height * 3))

    points = 640 * 480
    cloud = PointCloud2(
        header=Header(frame_id="lidar"), height=1, width=points,
        fields=[PointField(name=n, offset=4 * i, datatype=7, count=1) for i, n in enumerate("xyz")]
        + [PointField(name="intensity", offset=12, datatype=7, count=1)],
        is_bigendian=False, point_step=16, row_step=16 * points, data=os.urandom(16 * points),
        is_dense=True)
    return [
        ("String ('hello world')", "std_msgs/String", String(data="hello world")),
        ("Header", "std_msgs/Header", Header(seq=7, stamp=Time(1, 2), frame_id="base_link")),
        ("PoseStamped", "geometry_msgs/PoseStamped", pose),
        ("Image 640x480 rgb8", "sensor_msgs/Image", image(640, 480)),
        ("Image 1920x1080 rgb8", "sensor_msgs/Image", image(1920, 1080)),
        ("PointCloud2 307200 pts", "sensor_msgs/PointCloud2", cloud),
    ]


def minros_rates(msg: Any, seconds: float) -> Tuple[float, float, int]:
    data = msg.serialize_to_bytes()
    cls = type(msg)

    def ser() -> None:
        msg.serialize(io.BytesIO())

    def de() -> None:
        cls().deserialize(data)

    return best_rate(ser, seconds), best_rate(de, seconds), len(data)


def memcpy_rate(size: int, seconds: float) -> float:
    src = memoryview(os.urandom(size))
    return best_rate(lambda: bytes(src), seconds)


def worker() -> int:
    """``--worker``: answer ``{"case": i, "seconds": s}`` lines with minros rates (JSON)."""
    built = cases()
    for line in sys.stdin:
        req = json.loads(line)
        _label, _type, msg = built[req["case"]]
        ser, de, size = minros_rates(msg, req["seconds"])
        sys.stdout.write(json.dumps({"ser": ser, "de": de, "size": size}) + "\n")
        sys.stdout.flush()
    return 0


class SysMinros:
    """This script's ``--worker`` run by /usr/bin/python3 -S with only minros's src on the path."""

    def __init__(self) -> None:
        self.proc: subprocess.Popen | None = None
        if not os.path.exists(REFERENCE_PYTHON):
            return
        src = os.path.join(os.path.dirname(os.path.dirname(os.path.abspath(__file__))), "src")
        env = {"PATH": "/usr/bin:/bin", "PYTHONPATH": src, "HOME": os.environ.get("HOME", "/tmp")}
        self.proc = subprocess.Popen([REFERENCE_PYTHON, "-S", os.path.abspath(__file__), "--worker"],
                                     stdin=subprocess.PIPE, stdout=subprocess.PIPE, text=True, env=env)

    def rates(self, case: int, seconds: float) -> Dict | None:
        if self.proc is None:
            return None
        assert self.proc.stdin and self.proc.stdout
        self.proc.stdin.write(json.dumps({"case": case, "seconds": seconds}) + "\n")
        self.proc.stdin.flush()
        line = self.proc.stdout.readline()
        return json.loads(line) if line else None

    def close(self) -> None:
        if self.proc is not None:
            assert self.proc.stdin
            self.proc.stdin.close()
            self.proc.wait(10)


class Genpy:
    """Debian's genpy in a /usr/bin/python3 subprocess (the oracle's 'bench' request)."""

    def __init__(self) -> None:
        self.proc: subprocess.Popen | None = None
        self.note = ""
        if not os.path.exists(REFERENCE_PYTHON):
            self.note = f"{REFERENCE_PYTHON} not found"
            return
        env = {"PATH": "/usr/bin:/bin", "HOME": os.environ.get("HOME", "/tmp")}
        probe = subprocess.run([REFERENCE_PYTHON, "-c", "import genpy, sensor_msgs.msg"], env=env,
                               capture_output=True, timeout=60)
        if probe.returncode != 0:
            self.note = "Debian's genpy/sensor_msgs are not installed"
            return
        self.proc = subprocess.Popen([REFERENCE_PYTHON, "-c", GENPY_ORACLE], stdin=subprocess.PIPE,
                                     stdout=subprocess.PIPE, text=True, env=env)

    def rates(self, type_name: str, msg: Any, seconds: float) -> Dict | None:
        if self.proc is None:
            return None
        assert self.proc.stdin and self.proc.stdout
        self.proc.stdin.write(json.dumps({"op": "bench", "type": type_name, "value": to_plain(msg),
                                          "seconds": seconds}) + "\n")
        self.proc.stdin.flush()
        answer = json.loads(self.proc.stdout.readline())
        if "error" in answer:
            self.note = answer["error"]
            return None
        return answer

    def close(self) -> None:
        if self.proc is not None:
            assert self.proc.stdin
            self.proc.stdin.close()
            self.proc.wait(10)


def _fmt(rate: float | None) -> str:
    if rate is None:
        return "-"
    if rate >= 100000:
        return f"{rate / 1000:.0f}k"
    if rate >= 1000:
        return f"{rate / 1000:.1f}k"
    return f"{rate:.0f}"


def main(argv: List[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--seconds", type=float, default=0.1, help="time per measurement")
    parser.add_argument("--rounds", type=int, default=5,
                        help="alternating rounds per message; the best of each column is kept")
    parser.add_argument("--worker", action="store_true", help=argparse.SUPPRESS)
    args = parser.parse_args(argv)
    if args.worker:
        return worker()
    genpy = Genpy()
    sysmin = SysMinros()
    rows = []
    keys = ("ser", "sser", "gser", "de", "sde", "gde", "copy")
    try:
        for index, (label, type_name, msg) in enumerate(cases()):
            best = dict.fromkeys(keys, 0.0)
            size = 0
            for _ in range(args.rounds):
                ser, de, size = minros_rates(msg, args.seconds)
                best["ser"], best["de"] = max(best["ser"], ser), max(best["de"], de)
                ours = sysmin.rates(index, args.seconds)
                if ours:
                    best["sser"] = max(best["sser"], ours["ser"])
                    best["sde"] = max(best["sde"], ours["de"])
                theirs = genpy.rates(type_name, msg, args.seconds)
                if theirs:
                    best["gser"] = max(best["gser"], theirs["ser"])
                    best["gde"] = max(best["gde"], theirs["de"])
                if size > 100000:
                    best["copy"] = max(best["copy"], memcpy_rate(size, args.seconds))
            rows.append((label, size, [best[k] or None for k in keys]))
    finally:
        genpy.close()
        sysmin.close()
    header = ("message", "bytes", "ser minros", "ser m@sys", "ser genpy", "de minros", "de m@sys",
              "de genpy", "memcpy")
    print("messages per second, best of alternating rounds (higher is better)")
    print("m@sys = minros on /usr/bin/python3, the interpreter genpy runs on; memcpy = one copy")
    print("of the message's bytes (bytes(memoryview)), the floor for payloads returned as bytes")
    print(f"{header[0]:<24}{header[1]:>9}" + "".join(f"{h:>11}" for h in header[2:]))
    for label, size, values in rows:
        print(f"{label:<24}{size:>9}" + "".join(f"{_fmt(v):>11}" for v in values))
    if genpy.note:
        print(f"note: genpy columns skipped: {genpy.note}")
    print(f"minros: python {sys.version.split()[0]} ({sys.executable}); genpy and m@sys: {REFERENCE_PYTHON}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
