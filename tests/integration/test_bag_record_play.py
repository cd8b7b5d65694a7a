"""rosbag record and play options on a minros core: topic selection (-e, -x, --topics),
time selection (-s, -u, -r, -i), --clock, --pause with its keys, -l, buffer drops."""

from __future__ import annotations

import json
import os
import re
import subprocess
import time
from pathlib import Path

import pytest

from integration.pubsub_scripts import TALKER
from support import PYTHON, Proc, ros_env

COLLECT = r'''
import json, sys, time
import rospy
from rospy import AnyMsg
rospy.init_node("collect", anonymous=True)
got = []
def cb(msg, topic):
    got.append([topic, time.time(), msg._connection_header["type"]])
for topic in sys.argv[1].split(","):
    rospy.Subscriber(topic, AnyMsg, cb, callback_args=topic, tcp_nodelay=True)
print("ready", flush=True)
end = time.time() + float(sys.argv[2])
while time.time() < end and len(got) < int(sys.argv[3]):
    time.sleep(0.01)
time.sleep(0.3)
print(json.dumps(got), flush=True)
'''

MAKE = r'''
import sys
import rospy
from rosbag import Bag
from std_msgs.msg import String, Int32
with Bag(sys.argv[1], "w") as b:
    for i in range(50):
        b.write("/p", String("p%d" % i), rospy.Time(2000 + i // 10, (i % 10) * 100000000))
    for i in range(5):
        b.write("/q", Int32(i), rospy.Time(2000 + i, 50000000))
'''


def _bag(tmp_path: Path) -> Path:
    script = tmp_path / "make.py"
    script.write_text(MAKE)
    subprocess.run([PYTHON, str(script), str(tmp_path / "in.bag")], check=True, timeout=60)
    return tmp_path / "in.bag"


def _play(port: int, home: Path, tmp_path: Path, topics: str, expect: int, *args: str,
          stdin=subprocess.DEVNULL) -> tuple:
    script = tmp_path / "collect.py"
    script.write_text(COLLECT)
    collect = Proc([PYTHON, str(script), topics, "30", str(expect)], ros_env(port, home))
    try:
        collect.read_until("ready", 20)
        start = time.time()
        play = subprocess.run([PYTHON, "-m", "minros", "bag", "play", "in.bag", "-d", "0.5", *args],
                              env=ros_env(port, home), cwd=tmp_path, capture_output=True,
                              text=True, timeout=60, stdin=stdin)
        assert play.returncode == 0, play.stderr
        got = json.loads(collect.output(timeout=40).strip().splitlines()[-1])
    finally:
        collect.stop()
    return got, start, play


def test_play_selects_topics_and_time(minros_core, ros_home, tmp_path):
    _bag(tmp_path)
    got, _start, play = _play(minros_core, ros_home, tmp_path, "/p,/q", 5, "-i", "--topics", "/q")
    assert [g[0] for g in got] == ["/q"] * 5 and got[0][2] == "std_msgs/Int32"
    assert "Done." in play.stdout
    got, _start, _play_ = _play(minros_core, ros_home, tmp_path, "/p,/q", 23, "-r", "5", "-s", "1", "-u", "2")
    p = [g for g in got if g[0] == "/p"]
    assert len(p) == 21 and len([g for g in got if g[0] == "/q"]) == 2  # bag seconds 1..3 inclusive
    span = p[-1][1] - p[0][1]
    assert 0.3 < span < 0.6, span  # 2 s of bag at -r 5


def test_play_publishes_clock(minros_core, ros_home, tmp_path):
    _bag(tmp_path)
    script = tmp_path / "clock.py"
    script.write_text("import rospy\nfrom rosgraph_msgs.msg import Clock\n"
                      "rospy.init_node('c', anonymous=True)\n"
                      "m = rospy.wait_for_message('/clock', Clock, timeout=20)\n"
                      "print('clock', m.clock.to_sec(), flush=True)\n")
    waiter = Proc([PYTHON, str(script)], ros_env(minros_core, ros_home))
    try:
        time.sleep(1.0)
        play = subprocess.run([PYTHON, "-m", "minros", "bag", "play", "-q", "--clock", "-u", "1", "in.bag"],
                              env=ros_env(minros_core, ros_home), cwd=tmp_path, capture_output=True,
                              text=True, timeout=60)
        assert play.returncode == 0, play.stderr
        out = waiter.read_until("clock", 20)
    finally:
        waiter.stop()
    value = float(re.search(r"clock ([\d.]+)", out).group(1))
    assert 2000.0 <= value <= 2001.0


def test_play_pause_and_step_keys(minros_core, ros_home, tmp_path):
    _bag(tmp_path)
    master_fd, slave_fd = os.openpty()
    script = tmp_path / "collect.py"
    script.write_text(COLLECT)
    collect = Proc([PYTHON, str(script), "/q", "30", "5"], ros_env(minros_core, ros_home))
    player = None
    try:
        collect.read_until("ready", 20)
        player = subprocess.Popen([PYTHON, "-m", "minros", "bag", "play", "--pause", "-d", "0.5",
                                   "--topics", "/q", "--bags", "in.bag"], env=ros_env(minros_core, ros_home),
                                  cwd=tmp_path, stdin=slave_fd, stdout=subprocess.PIPE,
                                  stderr=subprocess.STDOUT, start_new_session=True)
        time.sleep(2.5)  # paused: nothing may arrive
        os.write(master_fd, b"s")  # one step
        time.sleep(1.0)
        os.write(master_fd, b" ")  # run
        player.wait(30)
        got = json.loads(collect.output(timeout=40).strip().splitlines()[-1])
        out = player.stdout.read().decode()
    finally:
        collect.stop()
        if player is not None and player.poll() is None:
            player.kill()
        os.close(master_fd)
        os.close(slave_fd)
    times = [g[1] for g in got]
    assert len(times) == 5 and "[PAUSED ]" in out and "Done." in out
    assert times[1] - times[0] > 0.5  # the step came alone, the rest after the space


@pytest.mark.smoke
def test_record_regex_exclude_and_drops(minros_core, ros_home, tmp_path):
    script = tmp_path / "talker.py"
    script.write_text(TALKER)
    env = ros_env(minros_core, ros_home)
    talkers = [Proc([PYTHON, str(script), topic, "string", "100000", "20", "0"], env)
               for topic in ("/a/x", "/a/y", "/b")]
    rec = Proc([PYTHON, "-m", "minros", "bag", "record", "-e", "/a/.*", "-x", "/a/y", "-O", "sel"],
               env, cwd=tmp_path)
    try:
        rec.read_until("Subscribing to /a/x", 20)
        time.sleep(1.5)
        out = rec.stop()
    finally:
        for t in talkers:
            t.stop()
    assert "Subscribing to /a/y" not in out and "Subscribing to /b" not in out
    from minros.bag import Bag

    with Bag(str(tmp_path / "sel.bag")) as bag:
        assert set(bag.get_type_and_topic_info().topics) == {"/a/x"}
        assert bag.get_message_count() >= 10


def test_record_buffer_overflow_counts_drops_per_topic(minros_core, ros_home, tmp_path):
    """-b 1 MB with 1080p frames: the recorder drops the oldest and says how many, per topic."""
    script = tmp_path / "talker.py"
    script.write_text(TALKER)
    env = ros_env(minros_core, ros_home)
    talker = Proc([PYTHON, str(script), "/cam", "image", "40", "200", "0"], env)
    rec = Proc([PYTHON, "-m", "minros", "bag", "record", "-b", "1", "--chunksize", "100000",
                "-j", "-O", "small", "/cam"], env, cwd=tmp_path)
    try:
        talker.read_until("sent 40", 60)
        time.sleep(0.5)
        out = rec.stop(timeout=120)
    finally:
        talker.stop()
    m = re.search(r"Dropped (\d+) messages because the buffer \(-b 1 MB\) was full: /cam: (\d+)", out)
    assert m and m.group(1) == m.group(2) and int(m.group(1)) > 0, out
    from minros.bag import Bag

    with Bag(str(tmp_path / "small.bag")) as bag:
        assert bag.get_message_count() + int(m.group(1)) <= 40


def _span(path: Path) -> tuple:
    """(message count, receive times' span in seconds) of a bag."""
    from minros.bag import Bag

    with Bag(str(path)) as bag:
        times = [t.to_sec() for _topic, _msg, t in bag.read_messages()]
    return len(times), (times[-1] - times[0]) if times else 0.0


def test_record_duration_ends_the_recording(minros_core, ros_home, tmp_path):
    """rosbag record --duration 2: the recorder stops by itself, with 2 s of messages."""
    script = tmp_path / "talker.py"
    script.write_text(TALKER)
    env = ros_env(minros_core, ros_home)
    talker = Proc([PYTHON, str(script), "/chatter", "string", "100000", "20", "0"], env)
    try:
        began = time.monotonic()
        rec = subprocess.run([PYTHON, "-m", "minros", "bag", "record", "--duration", "2", "-O",
                              "short", "/chatter"], env=env, cwd=tmp_path, capture_output=True,
                             text=True, timeout=30)
        took = time.monotonic() - began
    finally:
        talker.stop()
    assert rec.returncode == 0 and "Traceback" not in rec.stderr, rec.stdout + rec.stderr
    assert took >= 2.0
    count, span = _span(tmp_path / "short.bag")
    assert 20 <= count <= 41 and span <= 2.0, (count, span)  # 20 Hz for at most 2 s


def test_record_duration_ends_an_idle_recording(minros_core, ros_home, tmp_path):
    """Nothing published: the recording still ends after --duration (0.02m: 1.2 s), leaving
    the empty bag it opened at the start, as ROS's recorder does; a bad unit is one line."""
    env = ros_env(minros_core, ros_home)
    rec = subprocess.run([PYTHON, "-m", "minros", "bag", "record", "--duration", "0.02m", "-O",
                          "idle", "/nothing"], env=env, cwd=tmp_path, capture_output=True,
                         text=True, timeout=30)
    assert rec.returncode == 0 and "Traceback" not in rec.stderr, rec.stdout + rec.stderr
    assert _span(tmp_path / "idle.bag") == (0, 0.0)
    bad = subprocess.run([PYTHON, "-m", "minros", "bag", "record", "--duration", "3d", "/x"],
                         env=env, cwd=tmp_path, capture_output=True, text=True, timeout=30)
    assert bad.returncode == 1 and bad.stderr.startswith("Error reading options: Duration '3d'")
    assert "Traceback" not in bad.stderr and bad.stderr.count("\n") == 1, bad.stderr
