"""roslibpy (the PyPI rosbridge client) against `minros web`, run as a subprocess by
tests/integration/test_web.py: one scenario, one ``RESULT {json}`` line.

    python roslibpy_client.py WS_URL   (turtlesim must be running on the graph)
    python roslibpy_client.py WS_URL connect   (connects and asks rosapi the time)
    python roslibpy_client.py WS_URL refusing_service   (serves a service answering result false)
    python roslibpy_client.py WS_URL latched_twice   (two clients, one latched message each)
"""

from __future__ import annotations

import json
import sys
import threading
import time

import roslibpy


def main(url: str) -> int:
    out: dict = {}
    ros = roslibpy.Ros(url)
    ros.run(timeout=10)
    out["connected"] = ros.is_connected
    out["topics"] = ros.get_topics()
    out["topic_type"] = ros.get_topic_type("/turtle1/pose")
    out["nodes"] = ros.get_nodes()
    out["services"] = ros.get_services()
    out["service_type"] = ros.get_service_type("/spawn")
    out["message_details"] = ros.get_message_details("geometry_msgs/Twist")
    out["request_details"] = ros.get_service_request_details("turtlesim/Spawn")

    poses = []
    got_pose = threading.Event()

    def on_pose(msg: dict) -> None:
        poses.append(msg)
        got_pose.set()

    pose = roslibpy.Topic(ros, "/turtle1/pose", "turtlesim/Pose")
    pose.subscribe(on_pose)
    got_pose.wait(10)
    out["first_pose"] = poses[0] if poses else None
    cmd = roslibpy.Topic(ros, "/turtle1/cmd_vel", "geometry_msgs/Twist")
    cmd.advertise()
    for _ in range(15):
        cmd.publish(roslibpy.Message({"linear": {"x": 2.0, "y": 0.0, "z": 0.0},
                                      "angular": {"x": 0.0, "y": 0.0, "z": 0.0}}))
        time.sleep(0.1)
    time.sleep(1.0)
    out["last_pose"] = poses[-1] if poses else None
    pose.unsubscribe()
    cmd.unadvertise()

    spawn = roslibpy.Service(ros, "/spawn", "turtlesim/Spawn")
    out["spawn"] = spawn.call(roslibpy.ServiceRequest({"x": 2.0, "y": 3.0, "theta": 0.0,
                                                       "name": "webturtle"}), timeout=10)
    try:
        spawn.call(roslibpy.ServiceRequest({"x": "not a number"}), timeout=10)
        out["bad_call"] = "no error"
    except Exception as exc:
        out["bad_call"] = str(exc)

    param = roslibpy.Param(ros, "/web_test/gains")
    param.set({"kp": 1.5, "names": ["a", "b"]})
    out["param"] = param.get()
    out["param_names"] = ros.get_params()

    def add(request: dict, response: dict) -> bool:
        response["sum"] = request["a"] + request["b"]
        return True

    server = roslibpy.Service(ros, "/web_add", "rospy_tutorials/AddTwoInts")
    server.advertise(add)
    time.sleep(0.5)
    client = roslibpy.Service(ros, "/web_add", "rospy_tutorials/AddTwoInts")
    out["advertised_call"] = client.call(roslibpy.ServiceRequest({"a": 20, "b": 22}), timeout=10)
    server.unadvertise()
    out["time"] = ros.get_time()
    ros.terminate()
    print("RESULT " + json.dumps(out, default=dict), flush=True)
    return 0


def connect(url: str) -> int:
    ros = roslibpy.Ros(url)
    ros.run(timeout=10)
    out = {"connected": ros.is_connected, "time": ros.get_time()}
    ros.terminate()
    print("RESULT " + json.dumps(out, default=dict), flush=True)
    return 0


def refusing_service(url: str) -> int:
    """A service whose handler fills the response and returns False (roslibpy then sends
    ``result: false`` with the values), called through ROS."""
    ros = roslibpy.Ros(url)
    ros.run(timeout=10)

    def refuse(request: dict, response: dict) -> bool:
        response["sum"] = request["a"] + request["b"]
        return False

    server = roslibpy.Service(ros, "/web_refuse", "rospy_tutorials/AddTwoInts")
    server.advertise(refuse)
    time.sleep(0.5)
    out: dict = {}
    try:
        out["response"] = roslibpy.Service(ros, "/web_refuse", "rospy_tutorials/AddTwoInts").call(
            roslibpy.ServiceRequest({"a": 40, "b": 2}), timeout=10)
    except Exception as exc:
        out["error"] = str(exc)
    server.unadvertise()
    ros.terminate()
    print("RESULT " + json.dumps(out, default=dict), flush=True)
    return 0


def latched_twice(url: str) -> int:
    """Two clients subscribe to /web_latched one after the other (the first still subscribed):
    the latched message each gets, or None after 20 s."""
    out: dict = {"received": []}
    clients, topics = [], []
    for _ in range(2):
        ros = roslibpy.Ros(url)
        ros.run(timeout=10)
        clients.append(ros)
        got = threading.Event()
        received: list = []
        topic = roslibpy.Topic(ros, "/web_latched", "std_msgs/String")
        topic.subscribe(lambda msg, received=received, got=got: (received.append(msg), got.set()))
        topics.append(topic)
        got.wait(20)
        out["received"].append(received[0] if received else None)
    for topic in topics:
        topic.unsubscribe()
    clients[0].terminate()
    print("RESULT " + json.dumps(out, default=dict), flush=True)
    return 0


if __name__ == "__main__":
    scenario = sys.argv[2] if len(sys.argv) > 2 else "turtlesim"
    sys.exit({"turtlesim": main, "connect": connect, "refusing_service": refusing_service,
              "latched_twice": latched_twice}[scenario](sys.argv[1]))
