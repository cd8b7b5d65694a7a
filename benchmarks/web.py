#!/usr/bin/env python3
"""``minros web`` throughput and latency, beside the raw topic rates.

    .venv/bin/python benchmarks/web.py [--seconds 10]

Scenario 1, video: a minros publisher sends 1920x1080 bgr8 sensor_msgs/Image at 30 Hz. At the
same time, on one ``minros web``: a Foxglove client (node, Foxglove's @foxglove/ws-protocol and
@foxglove/rosmsg-serialization, tests/web/js) subscribed to the topic, an MJPEG viewer
(``/stream?topic=``) and two *stalled* clients that subscribed and then stopped reading (a
Foxglove client and an MJPEG viewer). The rates the two live clients receive are set beside the
raw topic rate a plain ROS subscriber sees. The server's --send-timeout is raised above the run
so the stalled clients stay connected throughout.

Scenario 2, small messages: a minros publisher sends 1,000 std_msgs/String per second, each
carrying its send time; rosbridge clients subscribed through ``minros web`` measure the delivered
rate and the latency (median, p99): roslibpy (the PyPI client) and a bare websockets client
(the floor of a Python client). Both run interleaved in the same server.

This file is also its own worker (``--role pub-image|pub-small|raw-sub``).
"""

from __future__ import annotations

import argparse
import json
import os
import socket
import statistics
import subprocess
import sys
import tempfile
import threading
import time
import urllib.request

from _bytecode import byte_compile_minros  # benchmarks/ is the script's directory: on sys.path

HERE = os.path.dirname(os.path.abspath(__file__))
REPO = os.path.dirname(HERE)
JS = os.path.join(REPO, "tests", "web", "js")
PYTHON = sys.executable


def free_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


# -- workers ---------------------------------------------------------------------------------

def role_pub_image(seconds: float) -> None:
    import minros
    from sensor_msgs.msg import Image

    minros.init_node("bench_camera", anonymous=True)
    pub = minros.Publisher("/camera/image_raw", Image, queue_size=2)
    img = Image(height=1080, width=1920, encoding="bgr8", step=1920 * 3)
    data = bytearray(os.urandom(1024)) * (1080 * 1920 * 3 // 1024)
    sent, period, start = 0, 1 / 30.0, time.monotonic()
    while not minros.is_shutdown() and time.monotonic() - start < seconds:
        data[0] = sent % 256
        img.data = bytes(data)
        img.header.stamp = minros.get_rostime()
        pub.publish(img)
        sent += 1
        delay = start + sent * period - time.monotonic()
        if delay > 0:
            time.sleep(delay)
    print(json.dumps({"sent": sent, "hz": sent / (time.monotonic() - start)}), flush=True)


def role_pub_small(seconds: float) -> None:
    import minros
    from std_msgs.msg import String

    minros.init_node("bench_small", anonymous=True)
    pub = minros.Publisher("/small", String, queue_size=100)
    sent, period, start = 0, 1 / 1000.0, time.monotonic()
    while not minros.is_shutdown() and time.monotonic() - start < seconds:
        pub.publish(String(str(time.time_ns())))
        sent += 1
        delay = start + sent * period - time.monotonic()
        if delay > 0:
            time.sleep(delay)
    print(json.dumps({"sent": sent, "hz": sent / (time.monotonic() - start)}), flush=True)


def role_raw_sub(topic: str, seconds: float) -> None:
    import minros

    minros.init_node("bench_raw_sub", anonymous=True)
    times: list = []
    minros.Subscriber(topic, minros.AnyMsg, lambda m: times.append(time.monotonic()))
    deadline = time.monotonic() + seconds
    while time.monotonic() < deadline and not minros.is_shutdown():
        time.sleep(0.05)
    hz = (len(times) - 1) / (times[-1] - times[0]) if len(times) > 1 else 0.0
    print(json.dumps({"hz": hz, "count": len(times)}), flush=True)


# -- clients ---------------------------------------------------------------------------------

def mjpeg_rate(url: str, seconds: float, out: dict) -> None:
    """Frames per second of an MJPEG stream over ``seconds`` (after the first frame)."""
    with urllib.request.urlopen(url, timeout=30) as response:
        data, frames, first, last = b"", 0, None, None
        while True:
            data += response.read1(1 << 20)
            while True:
                start = data.find(b"Content-Length: ")
                end = data.find(b"\r\n\r\n", start) if start >= 0 else -1
                if end < 0:
                    break
                length = int(data[start + 16:data.find(b"\r\n", start)])
                if len(data) < end + 4 + length:
                    break
                data = data[end + 4 + length:]
                now = time.monotonic()
                if first is None:
                    first = now
                else:
                    frames += 1
                    last = now
            if first is not None and time.monotonic() - first >= seconds:
                break
    out["hz"] = frames / (last - first) if last else 0.0


def stalled_mjpeg(url: str, stop: threading.Event) -> None:
    """An MJPEG viewer that reads the headers and then nothing."""
    host, port = url.split("//", 1)[1].split("/", 1)[0].split(":")
    sock = socket.create_connection((host, int(port)))
    sock.setsockopt(socket.SOL_SOCKET, socket.SO_RCVBUF, 4096)
    path = "/" + url.split("//", 1)[1].split("/", 1)[1]
    sock.sendall(f"GET {path} HTTP/1.1\r\nHost: {host}\r\n\r\n".encode())
    sock.recv(1024)
    stop.wait()
    sock.close()


def stalled_foxglove(ws_url: str, topic: str, stop: threading.Event) -> None:
    """A Foxglove client that subscribes and never reads again (the websockets client stops
    reading the socket once its small queue is full)."""
    from websockets.sync.client import connect

    with connect(ws_url, subprotocols=["foxglove.websocket.v1"], max_queue=2,
                 max_size=None) as ws:
        channel = None
        while channel is None:
            msg = json.loads(ws.recv(timeout=20))
            if msg.get("op") == "advertise":
                for ch in msg["channels"]:
                    if ch["topic"] == topic:
                        channel = ch["id"]
        ws.send(json.dumps({"op": "subscribe", "subscriptions": [{"id": 1, "channelId": channel}]}))
        stop.wait()


def roslibpy_latency(ws_url: str, seconds: float, out: dict) -> None:
    import roslibpy

    ros = roslibpy.Ros(ws_url)
    ros.run(timeout=10)
    lat: list = []
    topic = roslibpy.Topic(ros, "/small", "std_msgs/String", queue_length=1000)
    topic.subscribe(lambda m: lat.append((time.time_ns() - int(m["data"])) / 1e6))
    time.sleep(seconds)
    topic.unsubscribe()
    ros.close()
    out["lat"] = lat


def websockets_latency(ws_url: str, seconds: float, out: dict) -> None:
    from websockets.sync.client import connect

    lat: list = []
    with connect(ws_url) as ws:
        ws.send(json.dumps({"op": "subscribe", "topic": "/small", "type": "std_msgs/String",
                            "queue_length": 1000}))
        deadline = time.monotonic() + seconds
        while time.monotonic() < deadline:
            try:
                msg = json.loads(ws.recv(timeout=1))
            except TimeoutError:
                continue
            if msg.get("op") == "publish":
                lat.append((time.time_ns() - int(msg["msg"]["data"])) / 1e6)
    out["lat"] = lat


# -- the run ---------------------------------------------------------------------------------

def spawn(args: list, env: dict) -> subprocess.Popen:
    return subprocess.Popen(args, env=env, stdout=subprocess.PIPE, stderr=subprocess.STDOUT,
                            text=True, start_new_session=True)


def last_json(proc: subprocess.Popen, timeout: float) -> dict:
    out, _ = proc.communicate(timeout=timeout)
    for line in reversed(out.splitlines()):
        if line.startswith("{"):
            return json.loads(line)
    raise RuntimeError(out[-2000:])


def stop(proc: subprocess.Popen) -> None:
    import signal

    if proc.poll() is None:
        os.killpg(proc.pid, signal.SIGINT)
        try:
            proc.wait(10)
        except subprocess.TimeoutExpired:
            os.killpg(proc.pid, signal.SIGKILL)
            proc.wait(5)


def wait_for(predicate, timeout: float, what: str) -> None:
    deadline = time.monotonic() + timeout
    while not predicate():
        if time.monotonic() > deadline:
            raise RuntimeError(f"{what} not reached within {timeout} s")
        time.sleep(0.1)


def master_up(port: int) -> bool:
    import xmlrpc.client

    try:
        return xmlrpc.client.ServerProxy(f"http://127.0.0.1:{port}/").getPid("/b")[0] == 1
    except OSError:
        return False


def port_open(port: int) -> bool:
    try:
        socket.create_connection(("127.0.0.1", port), timeout=0.5).close()
        return True
    except OSError:
        return False


def run(seconds: float) -> list:
    home = tempfile.mkdtemp(prefix="minros-web-bench-")
    master, web_port = free_port(), free_port()
    env = dict(os.environ, ROS_MASTER_URI=f"http://localhost:{master}", ROS_HOSTNAME="localhost",
               ROS_HOME=home, ROS_LOG_DIR=home, PYTHONUNBUFFERED="1")
    me = os.path.abspath(__file__)
    procs = [spawn([PYTHON, "-m", "minros", "core", "-p", str(master)], env)]
    rows = []
    try:
        wait_for(lambda: master_up(master), 20, "the master")
        procs.append(spawn([PYTHON, "-m", "minros", "web", "--port", str(web_port),
                            "--send-timeout", str(seconds * 4 + 30)], env))
        wait_for(lambda: port_open(web_port), 20, "minros web")
        ws_url, http = f"ws://127.0.0.1:{web_port}", f"http://127.0.0.1:{web_port}"

        # 1: video
        span = seconds + 12
        pub = spawn([PYTHON, me, "--role", "pub-image", "--seconds", str(span)], env)
        raw = spawn([PYTHON, me, "--role", "raw-sub", "--topic", "/camera/image_raw",
                     "--seconds", str(seconds + 6)], env)
        time.sleep(3)
        halt = threading.Event()
        stalled = [threading.Thread(target=stalled_foxglove, args=(ws_url, "/camera/image_raw", halt), daemon=True),
                   threading.Thread(target=stalled_mjpeg, args=(f"{http}/stream?topic=/camera/image_raw", halt), daemon=True)]
        for t in stalled:
            t.start()
        time.sleep(1)
        mjpeg: dict = {}
        viewer = threading.Thread(target=mjpeg_rate, args=(f"{http}/stream?topic=/camera/image_raw", seconds, mjpeg))
        viewer.start()
        fox = subprocess.run(["node", os.path.join(JS, "foxglove_client.mjs"), "bench", ws_url,
                              "/camera/image_raw", str(seconds)], capture_output=True, text=True,
                             timeout=seconds + 60, env=dict(env, FOXGLOVE_CLIENT_TIMEOUT_MS=str(int((seconds + 50) * 1000))))
        viewer.join(seconds + 60)
        fox_line = [json.loads(x) for x in fox.stdout.splitlines() if x.startswith('{"bench"')]
        raw_hz = last_json(raw, seconds + 30)["hz"]
        pub_hz = last_json(pub, span + 30)["hz"]
        halt.set()
        fox_hz = fox_line[0]["bench"]["hz"] if fox_line else float("nan")
        decoded = fox_line[0]["bench"]["decodedOk"] if fox_line else False
        rows.append(("1080p bgr8 @30 Hz -> Foxglove client (node), 2 stalled clients", pub_hz, raw_hz,
                     fox_hz, None, f"decoded: {decoded}"))
        rows.append(("1080p bgr8 @30 Hz -> MJPEG viewer /stream, 2 stalled clients", pub_hz, raw_hz,
                     mjpeg.get("hz", float("nan")), None, "JPEG q95, encoded once per frame"))

        # 2: 1,000 small messages per second to rosbridge clients
        span = seconds + 8
        pub = spawn([PYTHON, me, "--role", "pub-small", "--seconds", str(span)], env)
        raw = spawn([PYTHON, me, "--role", "raw-sub", "--topic", "/small",
                     "--seconds", str(seconds + 4)], env)
        time.sleep(2)
        results = {"roslibpy": {}, "websockets": {}}
        clients = [threading.Thread(target=roslibpy_latency, args=(ws_url, seconds, results["roslibpy"])),
                   threading.Thread(target=websockets_latency, args=(ws_url, seconds, results["websockets"]))]
        for t in clients:
            t.start()
        for t in clients:
            t.join(seconds + 60)
        raw_hz = last_json(raw, seconds + 30)["hz"]
        pub_hz = last_json(pub, span + 30)["hz"]
        for name, label in (("roslibpy", "roslibpy (PyPI)"), ("websockets", "bare websockets client")):
            lat = sorted(results[name].get("lat", []))
            if not lat:
                rows.append((f"1,000 String/s -> rosbridge, {label}", pub_hz, raw_hz, 0.0, None, "nothing received"))
                continue
            hz = len(lat) / seconds
            p99 = lat[min(len(lat) - 1, int(len(lat) * 0.99))]
            rows.append((f"1,000 String/s -> rosbridge, {label}", pub_hz, raw_hz, hz,
                         (statistics.median(lat), p99), f"{len(lat)} msgs"))
    finally:
        for proc in reversed(procs):
            stop(proc)
    return rows


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--seconds", type=float, default=10.0)
    parser.add_argument("--role", help=argparse.SUPPRESS)
    parser.add_argument("--topic", help=argparse.SUPPRESS)
    args = parser.parse_args()
    if args.role == "pub-image":
        role_pub_image(args.seconds)
        return 0
    if args.role == "pub-small":
        role_pub_small(args.seconds)
        return 0
    if args.role == "raw-sub":
        role_raw_sub(args.topic, args.seconds)
        return 0
    byte_compile_minros()
    rows = run(args.seconds)
    print(f"minros web benchmark ({args.seconds:.0f} s per measurement, {os.cpu_count()} cores)")
    print(f"| {'scenario':<62} | published Hz | raw sub Hz | delivered Hz | latency median / p99 ms | note")
    print(f"|{'-' * 64}|--------------|------------|--------------|-------------------------|------")
    for name, pub_hz, raw_hz, hz, lat, note in rows:
        lat_text = f"{lat[0]:.1f} / {lat[1]:.1f}" if lat else "-"
        print(f"| {name:<62} | {pub_hz:12.1f} | {raw_hz:10.1f} | {hz:12.1f} | {lat_text:>23} | {note}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
