"""Test machinery for minros's ROS 2 side: network namespaces, the rclpy and Cyclone agents,
and the few CDR encodings the tests need, written by hand.

Every process that speaks DDS runs in a network namespace with only loopback (multicast
on), which the test creates as root and deletes afterwards: rclpy and cyclonedds are started
with ``ip netns exec``; minros runs in the test process itself, its sockets made in the
namespace (:meth:`Netns.entered` switches the calling thread there with ``setns`` while a
Context starts; sockets stay in the namespace they were made in). Nothing reaches eth0.
"""

from __future__ import annotations

import ctypes
import itertools
import json
import os
import queue
import re
import shutil
import struct
import subprocess
import threading
import time
from contextlib import contextmanager
from pathlib import Path
from typing import Dict, Iterator, List, Optional

import pytest

from support import IN_CI, need

REPO = Path(__file__).resolve().parent.parent
ROS2_HOME = Path(os.environ.get("MINROS_ROS2_HOME", "/opt/minros-ros2"))
AGENT = Path(__file__).with_name("ros2_agent.py")
CYCLONE_AGENT = Path(__file__).with_name("cyclone_agent.py")
INSTALLER = "scripts/install-ros2-reference.sh"

HASHES = {
    "std_msgs/msg/String": "RIHS01_df668c740482bbd48fb39d76a70dfd4bd59db1288021743503259e948f6b1a18",
    "sensor_msgs/msg/Image":
        "RIHS01_d31d41a9a4c4bc8eae9be757b0beed306564f7526c88ea6a4588fb9582527d47",
    "std_msgs/msg/UInt8MultiArray":
        "RIHS01_5687e861b8d307a5e48b7515467ae7a5fc2daf805bd0ce6d8e9e604bade9f385",
    "std_srvs/srv/SetBool_Request":
        "RIHS01_c62fbb99d94e1b25e8ef9e109f9581956bb1b3361a45a4e5810c36a90d29932e",
    "std_srvs/srv/SetBool_Response":
        "RIHS01_d0814e7f7b4880ab77e9c57426c7aa1562ab69f11eef8e2e968812f9cbd0b059",
    "std_srvs/srv/Trigger_Request":
        "RIHS01_d010825374ce8918e72bfd826c82603e60f45419e932ea976f807b74a863a199",
    "std_srvs/srv/Trigger_Response":
        "RIHS01_2d946c21e2fc3f1e9ca6986a8191d85fcc70097a8bb7771a053564bc47009cdf",
}

#: Cyclone 11.0.1 needs to be told to ignore Fast DDS's XTypes type information (spec 1b);
#: discovery stays on loopback (multicast on, as in the namespace)
CYCLONE_URI = ("<CycloneDDS><Domain><General><Interfaces><NetworkInterface name=\"lo\" "
               "multicast=\"true\"/></Interfaces></General><Compatibility>"
               "<IgnoreTypeInformation>1.15</IgnoreTypeInformation></Compatibility>"
               "</Domain></CycloneDDS>")


def ros2_python(distro: str) -> Path:
    return ROS2_HOME / distro / "bin" / "python"


def require_ros2(distro: str) -> None:
    """Skip locally (fail in CI) when the pip ROS 2 of ``distro`` is absent, or when this
    process cannot make network namespaces (root and iproute2)."""
    need(ros2_python(distro).exists(), f"the pip ROS 2 ({distro}) is not installed in "
                                       f"{ROS2_HOME}", INSTALLER)
    require_netns()


def require_netns() -> None:
    if os.geteuid() != 0 or shutil.which("ip") is None:
        if IN_CI:
            pytest.fail("the ROS 2 tests make network namespaces: they need root and iproute2")
        pytest.skip("network namespaces need root and iproute2")


_counter = itertools.count()
_libc = ctypes.CDLL(None, use_errno=True)
CLONE_NEWNET = 0x40000000


def _ip(*args: str) -> None:
    subprocess.run(["ip", *args], check=True, capture_output=True, timeout=20)


def _sweep() -> None:
    """Delete this helper's namespaces left by a run that was killed (their pid is gone and
    nothing runs in them)."""
    try:
        names = os.listdir("/var/run/netns")
    except OSError:
        return
    for name in names:
        found = re.fullmatch(r"mrtps(\d+)x\d+", name)
        if found is None or os.path.exists(f"/proc/{found.group(1)}"):
            continue
        pids = subprocess.run(["ip", "netns", "pids", name], capture_output=True, text=True)
        if pids.returncode == 0 and not pids.stdout.strip():
            subprocess.run(["ip", "netns", "del", name], capture_output=True, timeout=20)


class Netns:
    """A network namespace with only loopback, multicast on (DDS's discovery group routed to
    lo) unless ``multicast`` is False (as lo is outside a namespace: no multicast at all).
    Named uniquely (pid and a counter): other test runs share the machine."""

    def __init__(self, multicast: bool = True) -> None:
        _sweep()
        self.name = f"mrtps{os.getpid()}x{next(_counter)}"
        _ip("netns", "add", self.name)
        try:
            _ip("netns", "exec", self.name, "ip", "link", "set", "lo", "up")
            if multicast:
                _ip("netns", "exec", self.name, "ip", "link", "set", "lo", "multicast", "on")
                _ip("netns", "exec", self.name, "ip", "route", "add", "224.0.0.0/4", "dev", "lo")
        except Exception:
            self.delete()
            raise
        self.procs: List[subprocess.Popen] = []

    def argv(self, argv: List[str]) -> List[str]:
        return ["ip", "netns", "exec", self.name, *argv]

    @contextmanager
    def entered(self) -> Iterator[None]:
        """The calling thread in this namespace (sockets made meanwhile belong to it)."""
        own = os.open("/proc/thread-self/ns/net", os.O_RDONLY)
        target = os.open(f"/var/run/netns/{self.name}", os.O_RDONLY)
        try:
            if _libc.setns(target, CLONE_NEWNET) != 0:
                raise OSError(ctypes.get_errno(), "setns into the test's namespace")
            try:
                yield
            finally:
                if _libc.setns(own, CLONE_NEWNET) != 0:
                    raise OSError(ctypes.get_errno(), "setns back")
        finally:
            os.close(own)
            os.close(target)

    def delete(self) -> None:
        for proc in self.procs:
            if proc.poll() is None:
                proc.kill()
                proc.wait(5)
        subprocess.run(["ip", "netns", "del", self.name], capture_output=True, timeout=20)


def context(ns: Netns, **kwargs: object):
    """A minros ROS 2 Context whose sockets live in ``ns``."""
    from minros.ros2.rmw import Context

    with ns.entered():
        return Context(0, **kwargs)


def ros2_env(tmp: Path, extra: Optional[Dict[str, str]] = None) -> Dict[str, str]:
    env = {k: v for k, v in os.environ.items() if not k.startswith(("ROS_", "RMW_", "FASTDDS"))}
    env.pop("PYTHONPATH", None)
    env.update({"ROS_LOG_DIR": str(tmp / "ros2log"), "HOME": str(tmp),
                "RCUTILS_LOGGING_BUFFERED_STREAM": "0", "PYTHONUNBUFFERED": "1"})
    env.update(extra or {})
    return env


class Agent:
    """An rclpy (or cyclonedds) process in ``ns`` taking JSON commands."""

    def __init__(self, ns: Netns, python: Path, script: Path, name: str, tmp: Path,
                 env: Optional[Dict[str, str]] = None) -> None:
        self.proc = subprocess.Popen(ns.argv([str(python), str(script), name]),
                                     stdin=subprocess.PIPE, stdout=subprocess.PIPE,
                                     stderr=open(tmp / f"{name}.stderr", "wb"),
                                     env=ros2_env(tmp, env), text=True, bufsize=1)
        ns.procs.append(self.proc)
        self.stderr_path = tmp / f"{name}.stderr"
        self._lines: queue.Queue[Optional[str]] = queue.Queue()
        threading.Thread(target=self._pump, daemon=True).start()
        hello = self._read(60)
        self.pid = hello["pid"]

    def _pump(self) -> None:
        assert self.proc.stdout is not None
        for line in self.proc.stdout:
            self._lines.put(line)
        self._lines.put(None)

    def _read(self, timeout: float) -> dict:
        try:
            line = self._lines.get(timeout=timeout)
        except queue.Empty:
            raise AssertionError(f"the agent did not answer within {timeout} s; stderr: "
                                 f"{self.stderr()}") from None
        if line is None:
            raise AssertionError(f"the agent exited ({self.proc.poll()}); stderr: "
                                 f"{self.stderr()}")
        return json.loads(line)

    def stderr(self) -> str:
        try:
            return self.stderr_path.read_text()[-3000:]
        except OSError:
            return ""

    def __call__(self, op: str, **args: object) -> dict:
        """Send a command, wait for its answer (the command's own ``timeout`` plus 30 s)."""
        assert self.proc.stdin is not None
        self.proc.stdin.write(json.dumps({"op": op, **args}) + "\n")
        self.proc.stdin.flush()
        answer = self._read(float(args.get("timeout", 10)) + 30)
        if "error" in answer:
            raise AssertionError(f"agent {op}: {answer['error']}")
        return answer

    def close(self) -> None:
        if self.proc.poll() is None:
            try:
                assert self.proc.stdin is not None
                self.proc.stdin.write(json.dumps({"op": "quit"}) + "\n")
                self.proc.stdin.flush()
                self.proc.wait(10)
            except (OSError, subprocess.TimeoutExpired):
                self.proc.kill()
                self.proc.wait(5)


def wait_for(predicate, timeout: float, what: str, interval: float = 0.01):
    deadline = time.monotonic() + timeout
    while True:
        value = predicate()
        if value:
            return value
        if time.monotonic() > deadline:
            raise AssertionError(f"timed out after {timeout} s waiting for {what}")
        time.sleep(interval)


# -- CDR by hand -------------------------------------------------------------------------------

CDR_LE = b"\x00\x01\x00\x00"


def cdr_string(text: str) -> bytes:
    """std_msgs/String."""
    raw = text.encode() + b"\0"
    return CDR_LE + struct.pack("<I", len(raw)) + raw


def read_string(payload: bytes, offset: int = 4) -> str:
    """A CDR string at ``offset``; ValueError when it does not fit the payload."""
    (n,) = struct.unpack_from("<I", payload, offset)
    if n < 1 or offset + 4 + n > len(payload) or payload[offset + 3 + n] != 0:
        raise ValueError(f"a string of {n} bytes in a {len(payload)}-byte sample")
    return bytes(payload[offset + 4:offset + 3 + n]).decode()


class _Out:
    def __init__(self) -> None:
        self.b = bytearray()

    def align(self, n: int) -> None:
        self.b += b"\0" * (-len(self.b) % n)

    def u32(self, v: int) -> None:
        self.align(4)
        self.b += struct.pack("<I", v)

    def i32(self, v: int) -> None:
        self.align(4)
        self.b += struct.pack("<i", v)

    def u8(self, v: int) -> None:
        self.b += bytes((v,))

    def string(self, s: str) -> None:
        raw = s.encode() + b"\0"
        self.u32(len(raw))
        self.b += raw


def cdr_image(width: int, height: int, data: bytes, frame_id: str = "camera",
              encoding: str = "rgb8", stamp: tuple = (0, 0)) -> bytes:
    """sensor_msgs/Image: header (stamp, frame_id), height, width, encoding, is_bigendian,
    step, data."""
    o = _Out()
    o.i32(stamp[0])
    o.u32(stamp[1])
    o.string(frame_id)
    o.u32(height)
    o.u32(width)
    o.string(encoding)
    o.u8(0)
    o.u32(width * 3)
    o.u32(len(data))
    return CDR_LE + bytes(o.b) + data


def read_image(payload: memoryview) -> dict:
    """The fields of a serialized sensor_msgs/Image (the data as a view)."""
    view = memoryview(payload)
    pos = 4

    def u32() -> int:
        nonlocal pos
        pos += -(pos - 4) % 4
        (v,) = struct.unpack_from("<I", view, pos)
        pos += 4
        return v

    def string() -> str:
        nonlocal pos
        n = u32()
        text = bytes(view[pos:pos + n - 1]).decode()
        pos += n
        return text

    sec, nsec = u32(), u32()
    frame_id = string()
    height, width = u32(), u32()
    encoding = string()
    pos += 1  # is_bigendian
    step = u32()
    size = u32()
    return {"stamp": (sec, nsec), "frame_id": frame_id, "height": height, "width": width,
            "encoding": encoding, "step": step, "data": view[pos:pos + size]}


def cdr_setbool_request(data: bool) -> bytes:
    return CDR_LE + bytes((1 if data else 0,))


def cdr_setbool_response(success: bool, message: str) -> bytes:
    o = _Out()
    o.u8(1 if success else 0)
    o.string(message)
    return CDR_LE + bytes(o.b)


def read_setbool_response(payload: bytes) -> tuple:
    return bool(payload[4]), read_string(payload, 8)


CDR_TRIGGER_REQUEST = CDR_LE + b"\0"  # an empty struct is one byte (structure_needs_at_least_one_field)


def cdr_uint8_array(data: bytes) -> bytes:
    """std_msgs/UInt8MultiArray with no dimensions: dim (empty), data_offset 0, data."""
    return CDR_LE + struct.pack("<III", 0, 0, len(data)) + data


def read_uint8_array(payload: memoryview) -> memoryview:
    """The data of a std_msgs/UInt8MultiArray without dimensions."""
    view = memoryview(payload)
    dims, _, size = struct.unpack_from("<III", view, 4)
    if dims:
        raise ValueError("dimensions are not read here")
    return view[16:16 + size]


def cyclone_python() -> Path:
    return ROS2_HOME / "cyclonedds" / "bin" / "python"


def require_cyclone() -> None:
    need(cyclone_python().exists(), f"cyclonedds-python is not installed in {ROS2_HOME}",
         INSTALLER)
    require_netns()
