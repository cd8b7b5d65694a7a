"""Every script of examples/ that has no test of its own, run as a user runs it, on a
``minros core`` (the seed tutorials' scripts have theirs: test_pubsub_seeds.py,
test_add_two_ints.py, test_video_example.py)."""

from __future__ import annotations

import re
import subprocess

import pytest

from support import EXAMPLES, PYTHON, Proc, ros_env

README = (EXAMPLES / "README.md").read_text()


def _run(argv, env, timeout: float = 60.0) -> str:
    done = subprocess.run(argv, env=env, capture_output=True, text=True, timeout=timeout)
    output = done.stdout + done.stderr
    assert done.returncode == 0, output
    assert "Traceback" not in output, output
    return output


def test_every_example_is_in_the_readme():
    scripts = sorted(p.relative_to(EXAMPLES).as_posix() for p in EXAMPLES.rglob("*.py"))
    missing = [script for script in scripts if f"`{script}`" not in README]
    assert not missing, f"examples/README.md has no line for {missing}"


def test_talker_and_listener(minros_core, ros_home):
    env = ros_env(minros_core, ros_home)
    listener = Proc([PYTHON, str(EXAMPLES / "talker_listener/listener.py"), "--count", "3"], env)
    try:
        talker = _run([PYTHON, str(EXAMPLES / "talker_listener/talker.py"), "--count", "30",
                       "_rate:=50"], env)
        heard = listener.read_until("I heard", 20) + listener.read_until("I heard", 5)
    finally:
        heard_rest = listener.stop()
    assert re.search(r"\]: hello world 0$", talker, re.M), talker
    numbers = [int(n) for n in re.findall(r"I heard hello world (\d+)", heard + heard_rest)]
    assert len(numbers) >= 2 and numbers == sorted(numbers), heard + heard_rest


def test_turtlesim_square(minros_core, ros_home):
    env = ros_env(minros_core, ros_home, {"MINROS_HEADLESS": "1"})
    sim = Proc([PYTHON, "-m", "minros", "run", "turtlesim", "turtlesim_node"], env)
    try:
        out = _run([PYTHON, str(EXAMPLES / "turtlesim/draw_square.py"), "_side:=1.0",
                    "_speed:=4.0"], env)
    finally:
        sim.stop()
    corners = re.findall(r"corner (\d) at \(([\d.]+), ([\d.]+)\)", out)
    assert [c[0] for c in corners] == ["1", "2", "3", "4"], out
    start = re.search(r"start at \(([\d.]+), ([\d.]+)\)", out)
    x0, y0 = float(start.group(1)), float(start.group(2))
    expected = [(x0 + 1, y0), (x0 + 1, y0 + 1), (x0, y0 + 1), (x0, y0)]
    for (_n, x, y), (ex, ey) in zip(corners, expected):
        assert abs(float(x) - ex) < 0.05 and abs(float(y) - ey) < 0.05, out
    gap = float(re.search(r"square done: ([\d.]+) from the start", out).group(1))
    assert gap < 0.05, out


def test_tf_broadcaster_and_listener(minros_core, ros_home):
    env = ros_env(minros_core, ros_home)
    broadcaster = Proc([PYTHON, str(EXAMPLES / "tf/broadcaster.py")], env)
    try:
        out = _run([PYTHON, str(EXAMPLES / "tf/listener.py"), "--count", "2"], env)
    finally:
        broadcaster.stop()
    found = re.findall(r"moon from earth: \((-?[\d.]+), (-?[\d.]+)\), ([\d.]+) m; "
                       r"earth from moon: \((-?[\d.]+), (-?[\d.]+)\)", out)
    assert len(found) == 2, out
    for _x, _y, distance, ex, ey in found:
        # the moon is 2 m out and turns to face the earth: seen from it, the earth is 2 m ahead
        assert abs(float(distance) - 2.0) < 0.01, out
        assert abs(float(ex) - 2.0) < 0.01 and abs(float(ey)) < 0.01, out


def test_action_server_and_client(minros_core, ros_home):
    env = ros_env(minros_core, ros_home)
    server = Proc([PYTHON, str(EXAMPLES / "actionlib/countdown_server.py")], env)
    try:
        out = _run([PYTHON, str(EXAMPLES / "actionlib/countdown_client.py"), "3"], env)
    finally:
        server_out = server.stop()
    assert re.findall(r"feedback: (\d)", out) == ["3", "2", "1"], out
    assert "result: 3 (SUCCEEDED, 'lift-off')" in out, out
    assert "counting down from 3" in server_out


def test_bag_record_and_replay(minros_core, ros_home, tmp_path):
    env = ros_env(minros_core, ros_home)
    out = _run([PYTHON, str(EXAMPLES / "bag/record_replay.py"), "--dir", str(tmp_path)], env,
               timeout=90)
    recorded = [f"recorded {i}" for i in range(10)]
    assert re.search(r"messages:\s+10$", out, re.M), out
    assert f"== read back: {recorded}" in out, out
    assert f"== replayed: {recorded}" in out, out
    assert (tmp_path / "chatter.bag").stat().st_size > 0


def test_a_node_prints_its_own_trace(minros_core, ros_home):
    out = _run([PYTHON, str(EXAMPLES / "trace/own_trace.py")], ros_env(minros_core, ros_home))
    steps = re.findall(r"^\s*\[(\d)\]\s+\+\d", out, re.M)  # "[step] +seconds ..." lines
    # one node is publisher and subscriber: it registers both, the master tells it about
    # itself, it asks itself for the topic, connects to itself and sends itself 3 frames
    assert steps == ["1", "0", "2", "3", "4", "5", "5", "5", "6", "6", "6"], out
    assert '= {"data": "to myself 2"}' in out, out


@pytest.mark.smoke
def test_webcam_publisher_with_the_fake_camera(minros_core, ros_home):
    env = ros_env(minros_core, ros_home)
    sub = Proc([PYTHON, str(EXAMPLES / "video/video_sub.py")], env)
    pub = Proc([PYTHON, str(EXAMPLES / "video/fake_camera.py"), "--size", "320x240"], env)
    try:
        got = sub.read_until("receiving video frame", 30) + sub.read_until(
            "receiving video frame", 5)
        sent = pub.read_until("publishing video frame", 5)
    finally:
        pub_out = pub.stop()
        sub_out = sub.stop()
    assert got.count("receiving video frame") >= 2
    assert "publishing video frame" in sent
    assert "Traceback" not in pub_out + sub_out
