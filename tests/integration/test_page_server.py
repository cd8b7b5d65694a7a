"""The page's server side on a real master, without a browser: minros's master pushes graph
changes to minros web (no polling: a 60 s poll interval would never see them in time), and the
page's session streams a plot of a real topic."""

from __future__ import annotations

import json
import time
import xmlrpc.client

import pytest
from websockets.sync.client import connect

from support import PYTHON, Proc, free_port, ros_env

PAGE = "minros.page.v1"


def start_web(master_port: int, home, *args: str) -> tuple:
    port = free_port()
    proc = Proc([PYTHON, "-m", "minros", "web", "--port", str(port), *args], ros_env(master_port, home))
    proc.read_until("listening on", timeout=30)
    return proc, port


def frames_until(ws, predicate, timeout: float) -> dict:
    deadline = time.monotonic() + timeout
    while True:
        left = deadline - time.monotonic()
        assert left > 0, "no matching frame in time"
        msg = json.loads(ws.recv(timeout=left))
        if predicate(msg):
            return msg


@pytest.mark.smoke
def test_the_master_pushes_graph_changes_to_the_page(minros_core, ros_home):
    web, port = start_web(minros_core, ros_home, "--graph-interval", "60")
    master = xmlrpc.client.ServerProxy(f"http://127.0.0.1:{minros_core}/")
    try:
        with connect(f"ws://127.0.0.1:{port}/", subprotocols=[PAGE], open_timeout=10) as ws:
            assert ws.subprotocol == PAGE
            hello = json.loads(ws.recv(timeout=10))
            assert hello["op"] == "hello" and hello["graph_mode"] == "push"
            ws.send(json.dumps({"op": "graph_watch"}))
            first = frames_until(ws, lambda m: m["op"] == "graph", 10)
            assert "/minros_web" in first["nodes"]
            for i in range(3):
                started = time.monotonic()
                master.registerPublisher("/pushed", f"/pushed_{i}", "std_msgs/String", "http://127.0.0.1:9/")
                graph = frames_until(ws, lambda m, i=i: m["op"] == "graph" and any(
                    t["name"] == f"/pushed_{i}" for t in m["topics"]), 5)
                assert time.monotonic() - started < 2.0  # pushed: the poll interval is 60 s
                assert graph["mode"] == "push" and graph["version"] > first["version"]
            master.unregisterPublisher("/pushed", "/pushed_0", "http://127.0.0.1:9/")
            frames_until(ws, lambda m: m["op"] == "graph" and all(
                t["name"] != "/pushed_0" for t in m["topics"]), 5)
    finally:
        out = web.stop()
    assert "Traceback" not in out


def test_the_page_session_plots_a_real_topic(minros_core, ros_home):
    web, port = start_web(minros_core, ros_home)
    pub = Proc([PYTHON, "-m", "minros", "topic", "pub", "-r", "50", "/level", "std_msgs/Float64",
                "data: 2.5"], ros_env(minros_core, ros_home))
    try:
        with connect(f"ws://127.0.0.1:{port}/", subprotocols=[PAGE], open_timeout=10) as ws:
            json.loads(ws.recv(timeout=10))
            deadline = time.monotonic() + 15
            while True:  # until the publisher is registered
                ws.send(json.dumps({"op": "plot", "id": "p", "expr": "/level/data"}))
                reply = frames_until(ws, lambda m: m.get("id") == "p", 10)
                if "series" in reply or time.monotonic() > deadline:
                    break
                time.sleep(0.2)
            assert reply["series"] == ["/level/data"], reply
            data = frames_until(ws, lambda m: m["op"] == "plot_data" and m["data"], 10)["data"][0]
            assert data["topic"] == "/level" and set(data["y"][0]) == {2.5}
            assert abs(data["x"][0] - time.time()) < 5  # no header: the arrival time
            ws.send(json.dumps({"op": "stats_watch", "topics": ["/level"]}))
            stats = frames_until(ws, lambda m: m["op"] == "stats" and m["topics"]["/level"]["hz"], 10)
            assert 35 < stats["topics"]["/level"]["hz"] < 65
            assert stats["topics"]["/level"]["size"] == 8
    finally:
        pub.stop()
        out = web.stop()
    assert "Traceback" not in out


def test_a_dynamic_reconfigure_client_shares_a_topic_a_client_taps(minros_core, ros_home):
    """The web node's taps live outside its Subscribers (one receive thread for all): when the
    page's dynamic_reconfigure client subscribes to parameter_updates that a rosbridge client
    already taps, the tap moves to a Subscriber they share, and keeps delivering."""
    web, port = start_web(minros_core, ros_home)
    try:
        with connect(f"ws://127.0.0.1:{port}/", open_timeout=10) as bridge, \
                connect(f"ws://127.0.0.1:{port}/", subprotocols=[PAGE], open_timeout=10) as page:
            json.loads(page.recv(timeout=10))  # hello
            # a fake server: set_parameters through rosbridge, updates published by it too
            bridge.send(json.dumps({"op": "advertise_service", "service": "/fakedyn/set_parameters",
                                    "type": "dynamic_reconfigure/Reconfigure"}))
            bridge.send(json.dumps({"op": "advertise", "topic": "/fakedyn/parameter_updates",
                                    "type": "dynamic_reconfigure/Config", "latch": True}))
            bridge.send(json.dumps({"op": "advertise", "topic": "/fakedyn/parameter_descriptions",
                                    "type": "dynamic_reconfigure/ConfigDescription",
                                    "latch": True}))
            bridge.send(json.dumps({"op": "publish", "topic": "/fakedyn/parameter_descriptions",
                                    "latch": True, "msg": {"groups": [{
                                        "name": "Default", "type": "", "id": 0, "parent": 0,
                                        "parameters": [{"name": "n", "type": "int", "level": 0,
                                                        "description": "", "edit_method": ""}]}],
                                        "max": {"ints": [{"name": "n", "value": 9}]},
                                        "min": {"ints": [{"name": "n", "value": 0}]},
                                        "dflt": {"ints": [{"name": "n", "value": 1}]}}}))
            bridge.send(json.dumps({"op": "subscribe", "topic": "/fakedyn/parameter_updates",
                                    "type": "dynamic_reconfigure/Config"}))

            def update(value: int) -> dict:
                bridge.send(json.dumps({"op": "publish", "topic": "/fakedyn/parameter_updates",
                                        "msg": {"ints": [{"name": "n", "value": value}]}}))
                return frames_until(bridge, lambda m: m.get("op") == "publish", 1)

            deadline = time.monotonic() + 15
            while True:  # until the tap is connected to our own publisher
                try:
                    got = update(1)
                    break
                except (AssertionError, TimeoutError):
                    assert time.monotonic() < deadline, "the tap never delivered"
            assert got["msg"]["ints"] == [{"name": "n", "value": 1}]
            page.send(json.dumps({"op": "dynrec_get", "id": "d", "server": "/fakedyn"}))
            reply = frames_until(page, lambda m: m.get("id") == "d", 20)
            # the page's client got the fake server's description and configuration
            assert reply.get("config") == {"n": 1}, reply
            deadline = time.monotonic() + 15
            while True:  # the tap, now a shared Subscriber, delivers again
                try:
                    got = update(2)
                    if got["msg"]["ints"] == [{"name": "n", "value": 2}]:
                        break
                except (AssertionError, TimeoutError):
                    pass
                assert time.monotonic() < deadline, "the tap stopped delivering"
    finally:
        out = web.stop()
    assert "Traceback" not in out
