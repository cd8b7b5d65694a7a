"""interactive_markers: one server script, run unchanged by Debian's python3-interactive-markers
and by minros, is driven by the same Debian client (feedback like rviz sends: a drag, a menu
click, a second client's conflicting drag); the update_full and update messages it publishes,
and the callbacks it runs, are the same on both."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from support import PYTHON, REFERENCE_PYTHON, Proc, need, reference_env, reference_imports, ros_env

pytestmark = pytest.mark.interop

SERVER = r'''
import rospy
from interactive_markers.interactive_marker_server import InteractiveMarkerServer
from interactive_markers.menu_handler import MenuHandler
from visualization_msgs.msg import InteractiveMarker, InteractiveMarkerControl, InteractiveMarkerFeedback, Marker
from geometry_msgs.msg import Pose, Point

rospy.init_node("im_server")
server = InteractiveMarkerServer("demo", "_x")
menu = MenuHandler()

def on_feedback(fb):
    print("FEEDBACK %d %s %s %.2f" % (fb.event_type, fb.marker_name, fb.client_id, fb.pose.position.x), flush=True)
    server.applyChanges()

def on_check(fb):
    state = menu.getCheckState(fb.menu_entry_id)
    menu.setCheckState(fb.menu_entry_id, MenuHandler.UNCHECKED if state == MenuHandler.CHECKED else MenuHandler.CHECKED)
    print("MENU %d %s" % (fb.menu_entry_id, menu.getTitle(fb.menu_entry_id)), flush=True)
    menu.reApply(server)
    server.setPose("second", Pose(position=Point(x=5.0)))
    server.erase("third")
    server.applyChanges()

top = menu.insert("Top")
check = menu.insert("Check me", parent=top, callback=on_check)
menu.setCheckState(check, MenuHandler.UNCHECKED)
hidden = menu.insert("Hidden")
menu.setVisible(hidden, False)
for name, x in (("first", 1.0), ("second", 2.0), ("third", 3.0)):
    marker = InteractiveMarker()
    marker.header.frame_id = "base_link"
    marker.name = name
    marker.description = "marker " + name
    marker.pose.position.x = x
    control = InteractiveMarkerControl(name="move_x", interaction_mode=InteractiveMarkerControl.MOVE_AXIS)
    control.markers.append(Marker(type=Marker.CUBE))
    marker.controls.append(control)
    server.insert(marker, on_feedback)
menu.apply(server, "first")
server.applyChanges()
print("server ready", flush=True)
rospy.spin()
'''

CLIENT = r'''
import json, time
import rospy
from visualization_msgs.msg import InteractiveMarkerInit, InteractiveMarkerUpdate, InteractiveMarkerFeedback
from geometry_msgs.msg import Pose, Point

rospy.init_node("im_client")
log = []

def plain(m):
    return {"name": m.name, "x": round(m.pose.position.x, 3), "frame": m.header.frame_id,
            "description": getattr(m, "description", ""),
            "menu": [[e.id, e.parent_id, e.title, e.command_type] for e in getattr(m, "menu_entries", [])],
            "controls": [c.name for c in getattr(m, "controls", [])]}

def on_init(msg):
    log.append(["init", msg.server_id, msg.seq_num, sorted((plain(m) for m in msg.markers), key=lambda d: d["name"])])

def on_update(msg):
    if msg.type == InteractiveMarkerUpdate.KEEP_ALIVE:
        if not any(entry[0] == "keep_alive" for entry in log):
            log.append(["keep_alive", msg.server_id])
        return
    log.append(["update", msg.server_id, msg.seq_num,
                sorted((plain(m) for m in msg.markers), key=lambda d: d["name"]),
                sorted((plain(p) for p in msg.poses), key=lambda d: d["name"]), sorted(msg.erases)])

rospy.Subscriber("/demo/update_full", InteractiveMarkerInit, on_init)
rospy.Subscriber("/demo/update", InteractiveMarkerUpdate, on_update)
feedback = rospy.Publisher("/demo/feedback", InteractiveMarkerFeedback, queue_size=10)
deadline = time.time() + 30
while (feedback.get_num_connections() == 0 or not log) and time.time() < deadline:
    time.sleep(0.05)
time.sleep(1.2)  # a new marker refuses every client for 1 s (as if another had just moved it)

def send(event, marker, client, x=0.0, entry=0):
    fb = InteractiveMarkerFeedback(client_id=client, marker_name=marker, event_type=event, menu_entry_id=entry)
    fb.header.frame_id = "base_link"
    fb.pose = Pose(position=Point(x=x))
    feedback.publish(fb)
    time.sleep(0.4)

send(InteractiveMarkerFeedback.POSE_UPDATE, "first", "/rviz/a", x=1.5)
send(InteractiveMarkerFeedback.POSE_UPDATE, "first", "/rviz/b", x=9.0)  # refused: a moved it
send(InteractiveMarkerFeedback.MENU_SELECT, "first", "/rviz/a", entry=2)
send(InteractiveMarkerFeedback.BUTTON_CLICK, "nosuch", "/rviz/a")
time.sleep(0.8)
print("LOG " + json.dumps(log), flush=True)
'''


def _run(impl: str, tmp_path: Path, port: int, home: Path) -> tuple:
    server_script = tmp_path / f"server_{impl}.py"
    client_script = tmp_path / "client.py"
    server_script.write_text(SERVER)
    client_script.write_text(CLIENT)
    env = ros_env(port, home)
    if impl == "debian":
        server = Proc([REFERENCE_PYTHON, str(server_script)], reference_env(env))
    else:
        server = Proc([PYTHON, str(server_script)], env)
    client = None
    try:
        server.read_until("server ready", 30)
        client = Proc([REFERENCE_PYTHON, str(client_script)], reference_env(env))
        out = client.read_until("LOG ", 60)
        log = json.loads(out.split("LOG ", 1)[1].splitlines()[0])
    finally:
        if client is not None:
            client.stop()
        server_out = server.stop()
    callbacks = [line for line in server_out.splitlines() if line.startswith(("FEEDBACK", "MENU"))]
    return log, callbacks


def test_server_publishes_and_calls_back_as_debians(tmp_path: Path, debian_rosmaster: int,
                                                    ros_home: Path) -> None:
    need(reference_imports("interactive_markers.interactive_marker_server"),
         "Debian's python3-interactive-markers is not installed", "scripts/install-ros-reference.sh")
    debian_log, debian_callbacks = _run("debian", tmp_path, debian_rosmaster, ros_home)
    minros_log, minros_callbacks = _run("minros", tmp_path, debian_rosmaster, ros_home)
    # update and update_full are two topics: compare each one's sequence
    for kind in ("init", "update", "keep_alive"):
        assert [e for e in minros_log if e[0] == kind] == [e for e in debian_log if e[0] == kind]
    assert minros_callbacks == debian_callbacks
    # what the comparison covered
    assert ["keep_alive", "/im_server_x"] in minros_log
    assert minros_callbacks == ["FEEDBACK 1 first /rviz/a 1.50", "MENU 2 Check me"]
    inits = [entry for entry in minros_log if entry[0] == "init"]
    first = [m for m in inits[-1][3] if m["name"] == "first"][0]
    assert first["menu"] == [[1, 0, "Top", 0], [2, 1, "[x] Check me", 0]]
    assert [m["name"] for m in inits[-1][3]] == ["first", "second"]
