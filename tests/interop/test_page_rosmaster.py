"""minros web's page against Debian's rosmaster, which cannot push graph changes: the server
reads the graph every --graph-interval seconds instead, and the page still gets the changes."""

from __future__ import annotations

import json
import time
import xmlrpc.client

from websockets.sync.client import connect

from support import PYTHON, Proc, free_port, ros_env


def test_page_graph_is_polled_from_debian_rosmaster(debian_rosmaster, ros_home):
    port = free_port()
    web = Proc([PYTHON, "-m", "minros", "web", "--port", str(port), "--graph-interval", "0.5"],
               ros_env(debian_rosmaster, ros_home))
    master = xmlrpc.client.ServerProxy(f"http://127.0.0.1:{debian_rosmaster}/")
    banner = ""
    try:
        banner = web.read_until("listening on", timeout=30)
        with connect(f"ws://127.0.0.1:{port}/", subprotocols=["minros.page.v1"], open_timeout=10) as ws:
            hello = json.loads(ws.recv(timeout=10))
            assert hello["graph_mode"] == "poll"
            ws.send(json.dumps({"op": "graph_watch"}))
            master.registerPublisher("/polled", "/polled_topic", "std_msgs/String", "http://127.0.0.1:9/")
            deadline = time.monotonic() + 5
            while True:
                msg = json.loads(ws.recv(timeout=max(0.1, deadline - time.monotonic())))
                if msg["op"] == "graph" and any(t["name"] == "/polled_topic" for t in msg["topics"]):
                    break
            assert msg["mode"] == "poll"
    finally:
        out = banner + web.stop()
    assert "Traceback" not in out
    assert "graph: read every 0.5 s" in out
