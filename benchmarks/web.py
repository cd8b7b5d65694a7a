#!/usr/bin/env python3
"""``minros web`` throughput and latency, beside the raw topic rates.

    .venv/bin/python benchmarks/web.py [--seconds 10]

Scenario 1, video: a minros publisher sends 1920x1080 bgr8 sensor_msgs/Image at 30 Hz. At the
same time, on one ``minros web``: a Foxglove client (node, Foxglove's @foxglove/ws-protocol and
@foxglove/rosmsg-serialization, tests/web/js) subscribed to the topic, the page's image view
(the MJPEG stream ``/stream?topic=...&quality=80`` that ``images.js`` opens) and two *stalled*
clients that subscribed and then stopped reading (a Foxglove client and an MJPEG viewer). The
note says which transport the server's tap of the camera took (getBusInfo of /minros_web:
MINROSSHM between minros processes of one host, once the server connects through the node's
protocols). The rates the two live clients receive are set beside the
raw topic rate a plain ROS subscriber sees. The server's --send-timeout is raised above the run
so the stalled clients stay connected throughout.

Scenario 2, small messages: a minros publisher sends 1,000 std_msgs/String per second, each
carrying its send time; rosbridge clients subscribed through ``minros web`` measure the delivered
rate and the latency (median, p99): roslibpy (the PyPI client) and a bare websockets client
(the floor of a Python client). Both run interleaved in the same server.

Scenario 3, many topics (``--only topics``): publisher processes host 200 nodes with 10
std_msgs/String topics each, every topic published at 1 Hz; one rosbridge client subscribes to
all 2,000 through ``minros web``. Once every topic has delivered a message, the server's threads
and resident memory are read from /proc, and the delivered rate is measured.

Scenario 4, package files (``--only assets``): an attacker's 30 parallel GETs of a 46 MiB mesh
on ``/pkg/`` that it never reads, then six Foxglove clients asking for it eight times each
(``fetchAsset``) without reading. The server's resident memory idle, at its highest during
each flood and after the flood's clients closed, beside the time an honest client takes to
download the whole file meanwhile.

``--baseline DIR`` runs every scenario a second time, right after the first, with the server
from another source tree (an older commit: ``git archive COMMIT src stubs | tar -x -C DIR``),
for before/after figures on one machine in one run.

This file is also its own worker (``--role pub-image|pub-small|raw-sub|pub-farm``).
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


def role_pub_farm(index: int, nodes: int, per_node: int, rate: float, seconds: float) -> None:
    """``nodes`` nodes of ``per_node`` String topics each, in this one process (Node objects
    of their own: 200 processes would not fit the machine), each topic published at ``rate``."""
    from minros.client.publication import Publication
    from minros.node import Node
    from std_msgs.msg import String

    master = os.environ["ROS_MASTER_URI"]
    pubs = []
    for n in range(nodes):
        node = Node(argv=["farm", f"__master:={master}", "__hostname:=127.0.0.1"])
        name = f"farm{index}_{n}"
        node.init(name, args_key=(name,))
        for k in range(per_node):
            topic = f"/{name}/t{k}"
            impl = Publication(node, topic, topic, String)
            impl.queue_size = 2
            node.add_publication(impl)
            pubs.append(impl)
    print(json.dumps({"ready": len(pubs)}), flush=True)
    msg, sent, start = String("x" * 20), 0, time.monotonic()
    period = 1.0 / rate
    while time.monotonic() - start < seconds:
        tick = time.monotonic()
        for impl in pubs:
            impl.publish(msg)
            sent += 1
        delay = period - (time.monotonic() - tick)
        if delay > 0:
            time.sleep(delay)
    print(json.dumps({"sent": sent, "hz": sent / (time.monotonic() - start)}), flush=True)


def proc_stats(pid: int) -> dict:
    """Threads, resident and peak resident memory (MB) of process ``pid``."""
    status = {}
    with open(f"/proc/{pid}/status") as f:
        for line in f:
            key, _, value = line.partition(":")
            status[key] = value.strip()
    return {"threads": int(status["Threads"]), "rss": int(status["VmRSS"].split()[0]) / 1024,
            "peak": int(status["VmHWM"].split()[0]) / 1024}


def many_topics(ws_url: str, topics: list, seconds: float, server_pid: int, out: dict) -> None:
    """Subscribe one rosbridge client to every topic; when each has delivered a message, read
    the server's threads and memory, then count what arrives for ``seconds``."""
    from websockets.sync.client import connect

    with connect(ws_url, open_timeout=30, max_size=None) as ws:
        start = time.monotonic()
        for topic in topics:
            ws.send(json.dumps({"op": "subscribe", "topic": topic, "type": "std_msgs/String"}))
        seen: set = set()
        deadline = start + 120
        while len(seen) < len(topics) and time.monotonic() < deadline:
            try:
                seen.add(json.loads(ws.recv(timeout=5))["topic"])
            except TimeoutError:
                pass
        out["all_in"] = time.monotonic() - start
        out["seen"] = len(seen)
        out["settled"] = proc_stats(server_pid)
        count, t0 = 0, time.monotonic()
        while time.monotonic() - t0 < seconds:
            try:
                ws.recv(timeout=1)
                count += 1
            except TimeoutError:
                pass
        out["hz"] = count / (time.monotonic() - t0)
        out["end"] = proc_stats(server_pid)


def run_topics(seconds: float, nodes: int, per_node: int, farms: int, web_src: str | None) -> list:
    home = tempfile.mkdtemp(prefix="minros-web-bench-")
    master, web_port = free_port(), free_port()
    env = dict(os.environ, ROS_MASTER_URI=f"http://localhost:{master}", ROS_HOSTNAME="localhost",
               ROS_HOME=home, ROS_LOG_DIR=home, PYTHONUNBUFFERED="1")
    me = os.path.abspath(__file__)
    procs = [spawn([PYTHON, "-m", "minros", "core", "-p", str(master)], env)]
    try:
        wait_for(lambda: master_up(master), 20, "the master")
        web = spawn([PYTHON, "-m", "minros", "web", "--port", str(web_port)], web_env(env, web_src))
        procs.append(web)
        wait_for(lambda: port_open(web_port), 20, "minros web")
        idle = proc_stats(web.pid)
        span = seconds + 200
        farm_procs = []
        for index in range(farms):
            share = nodes // farms + (1 if index < nodes % farms else 0)
            farm = spawn([PYTHON, me, "--role", "pub-farm", "--index", str(index), "--nodes",
                          str(share), "--per-node", str(per_node), "--seconds", str(span)], env)
            farm_procs.append((farm, share))
            procs.append(farm)
        for farm, _share in farm_procs:
            line = farm.stdout.readline()
            if not line.startswith('{"ready"'):
                raise RuntimeError(f"a publisher farm did not start: {line}{farm.stdout.read()[-2000:]}")
        topics = [f"/farm{i}_{n}/t{k}" for i, (_f, share) in enumerate(farm_procs)
                  for n in range(share) for k in range(per_node)]
        out: dict = {}
        many_topics(f"ws://127.0.0.1:{web_port}", topics, seconds, web.pid, out)
    finally:
        for proc in reversed(procs):
            stop(proc)
    return [("idle server", 0, None, None, idle, idle),
            (f"{nodes} nodes x {per_node} topics, 1 Hz each, one rosbridge client", len(topics),
             out.get("all_in"), out.get("hz"), out.get("settled"), out.get("end"))]


def print_topics(rows: list, seconds: float) -> None:
    print(f"minros web, many topics ({seconds:.0f} s of delivery, {os.cpu_count()} cores; "
          "threads when all deliver / at the end)")
    print(f"| {'server':<10} | {'scenario':<56} | topics | all delivering after s | "
          "delivered msg/s | server threads | RSS MB | peak RSS MB")
    print(f"|{'-' * 12}|{'-' * 58}|--------|------------------------|-----------------|"
          "----------------|--------|------------")
    for who, (name, topics, all_in, hz, settled, end) in rows:
        all_text = f"{all_in:.1f}" if all_in is not None else "-"
        hz_text = f"{hz:.0f}" if hz is not None else "-"
        threads = f"{settled['threads']} / {end['threads']}" if settled else "-"
        rss = f"{settled['rss']:.0f}" if settled else "-"
        peak = f"{end['peak']:.0f}" if end else "-"
        print(f"| {who:<10} | {name:<56} | {topics:6d} | {all_text:>22} | {hz_text:>15} | "
              f"{threads:>14} | {rss:>6} | {peak:>11}")


def _rss_peak(pid: int, seconds: float) -> float:
    top, end = 0.0, time.monotonic() + seconds
    while time.monotonic() < end:
        top = max(top, proc_stats(pid)["rss"])
        time.sleep(0.05)
    return top


def _honest_get(url: str) -> tuple:
    start = time.monotonic()
    with urllib.request.urlopen(url, timeout=120) as response:
        size = len(response.read())
    return size, time.monotonic() - start


def _honest_fetch(ws_url: str, uri: str) -> tuple:
    from websockets.sync.client import connect

    start = time.monotonic()
    with connect(ws_url, subprotocols=["foxglove.websocket.v1"], max_size=None) as ws:
        ws.send(json.dumps({"op": "fetchAsset", "uri": uri, "requestId": 1}))
        while True:
            msg = ws.recv(timeout=120)
            if isinstance(msg, bytes) and msg[0] == 4:
                return len(msg) - 10, time.monotonic() - start


def _flood_pkg(web_port: int) -> list:
    unread = []
    for _ in range(30):
        sock = socket.create_connection(("127.0.0.1", web_port))
        sock.setsockopt(socket.SOL_SOCKET, socket.SO_RCVBUF, 4096)
        sock.sendall(f"GET /pkg/big_pkg/meshes/big.stl HTTP/1.1\r\nHost: 127.0.0.1:{web_port}"
                     "\r\n\r\n".encode())
        unread.append(sock)
    return unread


def _flood_foxglove(web_port: int) -> list:
    import warnings

    from websockets.sync.client import connect

    clients = []
    for _ in range(6):
        with warnings.catch_warnings():  # kept open past this function, on purpose
            warnings.simplefilter("ignore", DeprecationWarning)
            ws = connect(f"ws://127.0.0.1:{web_port}", subprotocols=["foxglove.websocket.v1"],
                         max_size=None)
        ws.socket.setsockopt(socket.SOL_SOCKET, socket.SO_RCVBUF, 4096)
        for request_id in range(8):
            ws.send(json.dumps({"op": "fetchAsset", "requestId": request_id,
                                "uri": "package://big_pkg/meshes/big.stl"}))
        clients.append(ws.socket)
    return clients


def run_assets(web_src: str | None) -> list:
    """Each flood on a server of its own (memory a flood leaves held would count twice)."""
    home = tempfile.mkdtemp(prefix="minros-web-bench-")
    pkg = os.path.join(home, "pkgs", "big_pkg")
    os.makedirs(os.path.join(pkg, "meshes"))
    with open(os.path.join(pkg, "package.xml"), "w") as f:
        f.write("<package><name>big_pkg</name></package>")
    with open(os.path.join(pkg, "meshes", "big.stl"), "wb") as f:
        f.write(os.urandom(46 << 20))
    master = free_port()
    env = dict(os.environ, ROS_MASTER_URI=f"http://localhost:{master}", ROS_HOSTNAME="localhost",
               ROS_HOME=home, ROS_LOG_DIR=home, PYTHONUNBUFFERED="1",
               ROS_PACKAGE_PATH=os.path.join(home, "pkgs"))
    procs = [spawn([PYTHON, "-m", "minros", "core", "-p", str(master)], env)]
    rows = []
    floods = [("30 unread GETs of a 46 MiB mesh on /pkg/", _flood_pkg, "GET"),
              ("6 unread Foxglove clients x 8 fetchAsset of it", _flood_foxglove, "fetchAsset")]
    try:
        wait_for(lambda: master_up(master), 20, "the master")
        for name, flood, honest in floods:
            web_port = free_port()
            web = spawn([PYTHON, "-m", "minros", "web", "--port", str(web_port)],
                        web_env(env, web_src))
            try:
                wait_for(lambda port=web_port: port_open(port), 20, "minros web")
                idle = proc_stats(web.pid)["rss"]
                socks = flood(web_port)
                peak = _rss_peak(web.pid, 5.0)
                if honest == "GET":
                    size, took = _honest_get(f"http://127.0.0.1:{web_port}/pkg/big_pkg/meshes/big.stl")
                else:
                    size, took = _honest_fetch(f"ws://127.0.0.1:{web_port}",
                                               "package://big_pkg/meshes/big.stl")
                for sock in socks:
                    sock.close()
                time.sleep(3)  # a measurement window: what is still held once they are gone
                rows.append((name, idle, peak, proc_stats(web.pid)["rss"], size, took, honest))
            finally:
                stop(web)
    finally:
        for proc in reversed(procs):
            stop(proc)
    return rows


def print_assets(rows: list) -> None:
    print(f"minros web, package files under a flood of unread downloads ({os.cpu_count()} cores; "
          "RSS of the server in MB)")
    print(f"| {'server':<10} | {'flood':<48} | RSS before | RSS peak | RSS after close | "
          "honest download meanwhile")
    print(f"|{'-' * 12}|{'-' * 50}|------------|----------|-----------------|"
          "--------------------------")
    for who, (name, idle, peak, after, size, took, honest) in sorted(rows, key=lambda r: r[1][0]):
        print(f"| {who:<10} | {name:<48} | {idle:10.0f} | {peak:8.0f} | {after:15.0f} | "
              f"{honest} of {size / 2**20:.0f} MiB in {took:.2f} s")


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


def tap_transport(master: int, topic: str) -> str:
    """The transport of ``minros web``'s subscription to ``topic`` (its getBusInfo)."""
    import xmlrpc.client

    try:
        uri = xmlrpc.client.ServerProxy(f"http://127.0.0.1:{master}/").lookupNode(
            "/bench", "/minros_web")[2]
        info = xmlrpc.client.ServerProxy(uri).getBusInfo("/bench")[2]
    except (OSError, IndexError, xmlrpc.client.Error):
        return "?"
    kinds = sorted({row[3] for row in info if row[4] == topic and row[2] == "i"})
    return "+".join(kinds) or "?"


def web_env(env: dict, web_src: str | None) -> dict:
    """The environment of the server: another source tree's minros first when asked."""
    return dict(env, PYTHONPATH=os.path.join(web_src, "src") + os.pathsep + os.path.join(
        web_src, "stubs")) if web_src else env


def run(seconds: float, web_src: str | None = None) -> list:
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
                            "--send-timeout", str(seconds * 4 + 30)], web_env(env, web_src)))
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
        tap = tap_transport(master, "/camera/image_raw")  # the stalled clients' tap, live
        mjpeg: dict = {}
        viewer = threading.Thread(target=mjpeg_rate, args=(
            f"{http}/stream?topic=/camera/image_raw&quality=80", seconds, mjpeg))
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
                     fox_hz, None, f"decoded: {decoded}; tap over {tap}"))
        rows.append(("1080p bgr8 @30 Hz -> the page's image view (/stream q80), 2 stalled",
                     pub_hz, raw_hz, mjpeg.get("hz", float("nan")), None,
                     f"JPEG encoded once per frame; tap over {tap}"))

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
    parser.add_argument("--only", choices=("streams", "topics", "assets"),
                        help="run scenarios 1-2 (streams), 3 (topics) or 4 (assets) only "
                             "(default: all)")
    parser.add_argument("--nodes", type=int, default=200, help="scenario 3: publisher nodes")
    parser.add_argument("--per-node", type=int, default=10, help="scenario 3: topics per node")
    parser.add_argument("--farms", type=int, default=4,
                        help="scenario 3: processes the publisher nodes share")
    parser.add_argument("--baseline", metavar="DIR",
                        help="also run each scenario with the server from this source tree "
                             "(its src/ and stubs/), e.g. an older commit git-archived there")
    parser.add_argument("--role", help=argparse.SUPPRESS)
    parser.add_argument("--topic", help=argparse.SUPPRESS)
    parser.add_argument("--index", type=int, default=0, help=argparse.SUPPRESS)
    args = parser.parse_args()
    if args.role == "pub-farm":
        role_pub_farm(args.index, args.nodes, args.per_node, 1.0, args.seconds)
        return 0
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
    contenders = [("this tree", None)] + ([("baseline", args.baseline)] if args.baseline else [])
    if args.only in (None, "assets"):
        print_assets([(who, row) for who, src in contenders for row in run_assets(src)])
        if args.only == "assets":
            return 0
    if args.only != "streams":
        rows = [(who, row) for who, src in contenders
                for row in run_topics(args.seconds, args.nodes, args.per_node, args.farms, src)]
        print_topics(rows, args.seconds)
        if args.only == "topics":
            return 0
    rows = [(who, row) for who, src in contenders for row in run(args.seconds, src)]
    print(f"minros web benchmark ({args.seconds:.0f} s per measurement, {os.cpu_count()} cores)")
    print(f"| {'server':<10} | {'scenario':<62} | published Hz | raw sub Hz | delivered Hz | "
          "latency median / p99 ms | note")
    print(f"|{'-' * 12}|{'-' * 64}|--------------|------------|--------------|"
          "-------------------------|------")
    for who, (name, pub_hz, raw_hz, hz, lat, note) in sorted(rows, key=lambda r: r[1][0]):
        lat_text = f"{lat[0]:.1f} / {lat[1]:.1f}" if lat else "-"
        print(f"| {who:<10} | {name:<62} | {pub_hz:12.1f} | {raw_hz:10.1f} | {hz:12.1f} | "
              f"{lat_text:>23} | {note}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
