"""minros <-> roscpp (a tiny C++ talker/listener built with g++ and pkg-config)."""

from __future__ import annotations

import hashlib
from pathlib import Path

import pytest

from integration.pubsub_scripts import LISTENER, TALKER
from support import PYTHON, Proc, build_roscpp, reference_env, ros_env

pytestmark = pytest.mark.interop

NODE_CPP = r'''
#include <ros/ros.h>
#include <std_msgs/String.h>
#include <geometry_msgs/PointStamped.h>
#include <sensor_msgs/Image.h>
#include <cstdio>
#include <cstdlib>
#include <string>

static int received = 0, wanted = 0;

static void done() { if (++received >= wanted) ros::shutdown(); }

static void onString(const ros::MessageEvent<std_msgs::String const>& event) {
  std::string who = event.getPublisherName();
  who = who.substr(0, who.find('_'));
  printf("got %s from %s\n", event.getMessage()->data.c_str(), who.c_str());
  fflush(stdout);
  done();
}

static void onStamped(const geometry_msgs::PointStamped::ConstPtr& m) {
  printf("got seq=%u stamp=%u.%u frame=%s x=%g\n", m->header.seq, m->header.stamp.sec,
         m->header.stamp.nsec, m->header.frame_id.c_str(), m->point.x);
  fflush(stdout);
  done();
}

static void onImage(const sensor_msgs::Image::ConstPtr& m) {
  printf("got seq=%u %ux%u %s len=%zu first=%d\n", m->header.seq, m->width, m->height,
         m->encoding.c_str(), m->data.size(), m->data.empty() ? -1 : (int)m->data[0]);
  fflush(stdout);
  done();
}

template <class M> static void talk(ros::NodeHandle& nh, const std::string& topic, int count,
                                    double hz, bool latch, M (*make)(int)) {
  ros::Publisher pub = nh.advertise<M>(topic, 10, latch);
  if (latch) {
    pub.publish(make(0));
    printf("published latched\n");
    fflush(stdout);
    ros::spin();
    return;
  }
  while (pub.getNumSubscribers() == 0 && ros::ok()) ros::Duration(0.01).sleep();
  printf("subscriber connected\n");
  fflush(stdout);
  ros::Rate rate(hz);
  for (int i = 0; i < count && ros::ok(); ++i) { pub.publish(make(i)); rate.sleep(); }
  printf("sent %d\n", count);
  fflush(stdout);
  ros::spin();
}

static std_msgs::String makeString(int i) {
  std_msgs::String m; m.data = "msg " + std::to_string(i); return m;
}
static geometry_msgs::PointStamped makeStamped(int i) {
  geometry_msgs::PointStamped m; m.header.stamp = ros::Time(1000 + i, 5);
  m.header.frame_id = "map"; m.point.x = i; return m;
}
static sensor_msgs::Image makeImage(int i) {
  sensor_msgs::Image m; m.height = 1080; m.width = 1920; m.encoding = "bgr8"; m.step = 1920 * 3;
  m.header.frame_id = "cam"; m.data.assign(1920 * 1080 * 3, (unsigned char)(i % 251)); return m;
}

int main(int argc, char** argv) {
  // same argument order as the Python scripts: listener TOPIC KIND COUNT | talker TOPIC KIND COUNT HZ LATCH
  std::string mode = argv[1];
  ros::init(argc, argv, mode, ros::init_options::AnonymousName);
  ros::NodeHandle nh;
  std::string topic = argv[2], kind = argv[3];
  int count = atoi(argv[4]);
  if (mode == "listener") {
    wanted = count;
    ros::Subscriber sub;
    if (kind == "string") sub = nh.subscribe(topic, 100, onString);
    else if (kind == "stamped") sub = nh.subscribe(topic, 100, onStamped);
    else sub = nh.subscribe(topic, 10, onImage);
    printf("subscribed\n");
    fflush(stdout);
    ros::spin();
    printf("listener done %d\n", received);
    return 0;
  }
  double hz = atof(argv[5]);
  bool latch = atoi(argv[6]) != 0;
  if (kind == "string") talk(nh, topic, count, hz, latch, makeString);
  else if (kind == "stamped") talk(nh, topic, count, hz, latch, makeStamped);
  else talk(nh, topic, count, hz, latch, makeImage);
  return 0;
}
'''


@pytest.fixture(scope="session")
def roscpp_node(tmp_path_factory) -> Path:
    """The C++ talker/listener, compiled once per session."""
    return build_roscpp(NODE_CPP, "pubsub_node", tmp_path_factory.mktemp("roscpp"),
                        ("roscpp", "std_msgs", "geometry_msgs", "sensor_msgs"))


@pytest.fixture
def scripts(tmp_path: Path):
    talker = tmp_path / "talker.py"
    listener = tmp_path / "listener.py"
    talker.write_text(TALKER)
    listener.write_text(LISTENER)
    return talker, listener


def _start(impl, scripts, binary, role, args, port, home) -> Proc:
    if impl == "roscpp":
        return Proc([str(binary), role, *map(str, args)], reference_env(ros_env(port, home)))
    script = scripts[0] if role == "talker" else scripts[1]
    return Proc([PYTHON, str(script), *map(str, args)], ros_env(port, home))


def _exchange(impls, scripts, binary, port, home, kind, count, hz=50, latch=False):
    pub_impl, sub_impl = impls
    topic = f"/{'l' if latch else 't'}_{kind}"
    procs = []
    try:
        if latch:
            pub = _start(pub_impl, scripts, binary, "talker", [topic, kind, 1, hz, 1], port, home)
            procs.append(pub)
            pub.read_until("published latched", 20)
            sub = _start(sub_impl, scripts, binary, "listener", [topic, kind, count], port, home)
            procs.append(sub)
        else:
            sub = _start(sub_impl, scripts, binary, "listener", [topic, kind, count], port, home)
            procs.append(sub)
            sub.read_until("subscribed", 20)
            procs.append(_start(pub_impl, scripts, binary, "talker", [topic, kind, count, hz, 0], port, home))
        out = sub.read_until(f"listener done {count}", 30)
        return [line for line in out.splitlines() if line.startswith("got ")]
    finally:
        for proc in procs:
            proc.stop()


PAIRS = [("minros", "roscpp"), ("roscpp", "minros")]


@pytest.mark.parametrize("impls", PAIRS, ids=["minros-to-roscpp", "roscpp-to-minros"])
def test_strings(roscpp_node, scripts, debian_rosmaster, ros_home, impls):
    got = _exchange(impls, scripts, roscpp_node, debian_rosmaster, ros_home, "string", 20)
    assert got == [f"got msg {i} from /talker" for i in range(20)]


@pytest.mark.parametrize("impls", PAIRS, ids=["minros-to-roscpp", "roscpp-to-minros"])
def test_latched(roscpp_node, scripts, debian_rosmaster, ros_home, impls):
    got = _exchange(impls, scripts, roscpp_node, debian_rosmaster, ros_home, "string", 1, latch=True)
    assert got == ["got msg 0 from /talker"]


@pytest.mark.parametrize("impls", PAIRS, ids=["minros-to-roscpp", "roscpp-to-minros"])
def test_header_stamped(roscpp_node, scripts, debian_rosmaster, ros_home, impls):
    got = _exchange(impls, scripts, roscpp_node, debian_rosmaster, ros_home, "stamped", 5)
    # both libraries number header.seq per publisher (roscpp from 0? it fills seq too)
    seqs = [int(line.split()[1].split("=")[1]) for line in got]
    assert seqs == list(range(seqs[0], seqs[0] + 5))
    assert [line.split(" ", 2)[2] for line in got] == [
        f"stamp={1000 + i}.5 frame=map x={i}" for i in range(5)]


@pytest.mark.parametrize("impls", PAIRS, ids=["minros-to-roscpp", "roscpp-to-minros"])
def test_1080p_images(roscpp_node, scripts, debian_rosmaster, ros_home, impls):
    got = _exchange(impls, scripts, roscpp_node, debian_rosmaster, ros_home, "image", 3, hz=10)
    size = 1920 * 1080 * 3
    assert len(got) == 3
    for i, line in enumerate(got):
        assert f"1920x1080 bgr8 len={size} first={i}" in line
        if impls[1] == "minros":
            assert f"md5={hashlib.md5(bytes([i]) * size).hexdigest()[:12]}" in line
