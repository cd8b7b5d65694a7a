"""topic_tools on minros next to Debian's (C++ relay, drop, throttle, mux; Python mux_select)
on one Debian rosmaster: our programs, started with `rosrun topic_tools ...`, forward a Debian
publisher's messages under their real type to Debian subscribers; drop and throttle pass what
Debian's own programs pass on the same input; Debian's mux_select/mux_list drive our mux and
ours drive Debian's mux; transform publishes an expression of each message."""

from __future__ import annotations

import json
import os
import subprocess
from pathlib import Path

import pytest

from support import (
    PYTHON,
    REFERENCE_PYTHON,
    Proc,
    need,
    reference_env,
    ros_env,
)

pytestmark = pytest.mark.interop

ROSRUN = str(Path(PYTHON).parent / "rosrun")
DEBIAN_TOOLS = "/usr/lib/topic_tools"

# Waits for every expected subscriber, publishes 40 numbered messages at 50 Hz, and prints
# what each output topic received (a Debian rospy subscriber: the handshake checks the type).
PROBE = r'''
import json, sys, time
import rospy
from std_msgs.msg import Int32
outputs = sys.argv[1].split(",")
subscribers_wanted = int(sys.argv[2])
rospy.init_node("probe")
got = {t: [] for t in outputs}
for t in outputs:
    rospy.Subscriber(t, Int32, lambda m, t=t: got[t].append(m.data))
pub = rospy.Publisher("/numbers", Int32, queue_size=100)
deadline = time.time() + 30
while pub.get_num_connections() < subscribers_wanted and time.time() < deadline:
    time.sleep(0.05)
# The outputs are advertised by their first message: warm up until every output delivers,
# then count from a clean slate (both drops have seen the same warm-up messages).
deadline = time.time() + 30
while not all(got.values()) and time.time() < deadline:
    pub.publish(Int32(data=-1))
    time.sleep(0.1)
time.sleep(0.5)
for t in outputs:
    got[t] = []
for i in range(40):
    pub.publish(Int32(data=i))
    time.sleep(0.02)
time.sleep(1.0)
print("GOT " + json.dumps(got), flush=True)
'''


def _debian_tools_present() -> None:
    need(all(os.access(f"{DEBIAN_TOOLS}/{t}", os.X_OK) for t in ("relay", "drop", "mux")),
         "Debian's topic-tools programs are not installed", "scripts/install-ros-reference.sh")


def test_relay_drop_throttle_transform_next_to_debians(tmp_path: Path, debian_rosmaster: int,
                                                       ros_home: Path) -> None:
    _debian_tools_present()
    env = ros_env(debian_rosmaster, ros_home)
    denv = reference_env(env)
    procs = [
        Proc([ROSRUN, "topic_tools", "relay", "/numbers", "/relayed"], env),
        Proc([ROSRUN, "topic_tools", "drop", "/numbers", "2", "3", "/dropped"], env),
        Proc([f"{DEBIAN_TOOLS}/drop", "/numbers", "2", "3", "/dropped_debian"], denv),
        Proc([ROSRUN, "topic_tools", "throttle", "messages", "/numbers", "10", "/slow"], env),
        Proc([f"{DEBIAN_TOOLS}/throttle", "messages", "/numbers", "10", "/slow_debian"], denv),
        Proc([ROSRUN, "topic_tools", "transform", "/numbers", "/doubled", "std_msgs/Int32",
              "m.data * 2", "--wait-for-start"], env),
    ]
    probe_script = tmp_path / "probe.py"
    probe_script.write_text(PROBE)
    outputs = "/relayed,/dropped,/dropped_debian,/slow,/slow_debian,/doubled"
    try:
        # transform subscribes once /numbers is published: the probe waits for 5 first
        probe = Proc([REFERENCE_PYTHON, str(probe_script), outputs, "6"], denv)
        procs.append(probe)
        out = probe.read_until("GOT ", 60)
        got = json.loads(out.split("GOT ", 1)[1].splitlines()[0])
        assert got["/relayed"] == list(range(40)), got
        assert got["/dropped"] == got["/dropped_debian"], got
        assert len(got["/dropped"]) in (13, 14), got  # one in three passes
        assert got["/doubled"] == [2 * i for i in range(40)]
        # 40 messages 20 ms apart through a 10 Hz throttle: one in five, as Debian's passes
        assert 6 <= len(got["/slow"]) <= 10 and abs(len(got["/slow"]) - len(got["/slow_debian"])) <= 2
    finally:
        for proc in procs:
            proc.stop()


MUX_PROBE = r'''
import json, subprocess, sys, time
import rospy
from std_msgs.msg import String
rospy.init_node("mux_probe")
mux_name = sys.argv[1]
got, selected = [], []
rospy.Subscriber("/out", String, lambda m: got.append(m.data))
rospy.Subscriber(mux_name + "/selected", String, lambda m: selected.append(m.data))
pubs = {t: rospy.Publisher(t, String, queue_size=10) for t in ("/a", "/b")}
deadline = time.time() + 30
while any(p.get_num_connections() == 0 for p in pubs.values()) and time.time() < deadline:
    time.sleep(0.05)

def burst(tag):
    for _ in range(10):
        for t, p in pubs.items():
            p.publish(String(data=tag + t))
        time.sleep(0.03)
    time.sleep(0.5)

burst("one")
print("TOOL " + json.dumps(sys.argv[2:]), flush=True)
tool = lambda *args: subprocess.run(list(args), capture_output=True, text=True, timeout=30)
select = tool(*sys.argv[2].split(), mux_name, "/b")
burst("two")
listing = tool(*sys.argv[3].split(), mux_name)
print("RESULT " + json.dumps({"got": got, "selected": selected, "select_out": select.stdout,
      "select_rc": select.returncode, "list_out": listing.stdout}), flush=True)
'''


@pytest.mark.parametrize("mux_side", ["minros", "debian"])
def test_mux_driven_by_the_other_sides_tools(tmp_path: Path, debian_rosmaster: int,
                                             ros_home: Path, mux_side: str) -> None:
    _debian_tools_present()
    env = ros_env(debian_rosmaster, ros_home)
    denv = reference_env(env)
    if mux_side == "minros":
        mux = Proc([ROSRUN, "topic_tools", "mux", "/out", "/a", "/b", "mux:=/sel"], env)
        tools = [f"{REFERENCE_PYTHON} {DEBIAN_TOOLS}/mux_select",
                 f"{REFERENCE_PYTHON} {DEBIAN_TOOLS}/mux_list"]
        tool_env = denv
    else:
        mux = Proc([f"{DEBIAN_TOOLS}/mux", "/out", "/a", "/b", "mux:=/sel"], denv)
        tools = [f"{ROSRUN} topic_tools mux_select", f"{ROSRUN} topic_tools mux_list"]
        tool_env = env
    probe_script = tmp_path / "mux_probe.py"
    probe_script.write_text(MUX_PROBE)
    probe = None
    try:
        probe = Proc([REFERENCE_PYTHON, str(probe_script), "/sel", *tools],
                     {**denv, "PATH": tool_env["PATH"]} if mux_side == "debian" else denv)
        out = probe.read_until("RESULT ", 60)
        result = json.loads(out.split("RESULT ", 1)[1].splitlines()[0])
        got = result["got"]
        assert result["select_rc"] == 0, result
        assert "one/a" in got and "one/b" not in got, got
        assert "two/b" in got and "two/a" not in got, got
        assert result["selected"][-1] == "/b", result
        assert "/a" in result["list_out"] and "/b" in result["list_out"], result
    finally:
        if probe is not None:
            probe.stop()
        mux.stop()


LAUNCH = """<launch>
  <node pkg="topic_tools" type="relay" name="chatter_relay" args="/chatter /chatter_relayed"/>
  <node pkg="topic_tools" type="throttle" name="chatter_throttle"
        args="messages /chatter 2.0 /chatter_slow"/>
</launch>
"""


def test_programs_start_from_a_launch_file(tmp_path: Path, debian_rosmaster: int,
                                           ros_home: Path) -> None:
    launch = tmp_path / "relay.launch"
    launch.write_text(LAUNCH)
    env = ros_env(debian_rosmaster, ros_home)
    denv = reference_env(env)
    roslaunch = Proc([str(Path(PYTHON).parent / "roslaunch"), str(launch)], env)
    talker = Proc(["/usr/bin/rostopic", "pub", "-r", "20", "/chatter", "std_msgs/String",
                   "data: hi"], denv)
    try:
        for topic in ("/chatter_relayed", "/chatter_slow"):
            echo = subprocess.run(["/usr/bin/rostopic", "echo", "-n", "1", topic], env=denv,
                                  capture_output=True, text=True, timeout=60)
            assert echo.stdout.startswith('data: "hi"'), echo
        info = subprocess.run(["/usr/bin/rosnode", "list"], env=denv, capture_output=True,
                              text=True, timeout=30).stdout
        assert "/chatter_relay" in info and "/chatter_throttle" in info, info
    finally:
        talker.stop()
        roslaunch.stop()
