"""tf2's BufferCore semantics in minros.tf.core: caches, interpolation, latest common time,
static frames, exception classes and texts, insert checks and their rate limit.

Texts and numbers asserted here were read off Debian's tf2_py for the same requests
(tests/interop/test_tf_interop.py compares the two on random trees)."""

from __future__ import annotations

import logging
import math
import threading
import time

import pytest

import rospy
from geometry_msgs.msg import TransformStamped
from minros.tf import core as tfcore
from minros.tf.buffer import Buffer
from minros.tf.core import BufferCore
from tf2_py import (
    ConnectivityException,
    ExtrapolationException,
    InvalidArgumentException,
    LookupException,
    TransformException,
)


def stamped(parent, child, secs, nsecs=0, xyz=(0.0, 0.0, 0.0), q=(0.0, 0.0, 0.0, 1.0)):
    t = TransformStamped()
    t.header.frame_id = parent
    t.child_frame_id = child
    t.header.stamp = rospy.Time(secs, nsecs)
    t.transform.translation.x, t.transform.translation.y, t.transform.translation.z = xyz
    r = t.transform.rotation
    r.x, r.y, r.z, r.w = q
    return t


def yaw(angle):
    return (0.0, 0.0, math.sin(angle / 2), math.cos(angle / 2))


class Log:
    """Collects what BufferCore reports."""

    def __init__(self):
        self.lines = []

    def __call__(self, level, text):
        self.lines.append((level, text))


def values(msg):
    t, r = msg.transform.translation, msg.transform.rotation
    return [t.x, t.y, t.z, r.x, r.y, r.z, r.w]


def test_interpolates_translation_linearly_and_rotation_by_slerp():
    core = BufferCore()
    core.set_transform(stamped("world", "robot", 10, xyz=(0, 0, 0), q=yaw(0.0)), "a")
    core.set_transform(stamped("world", "robot", 12, xyz=(2, 4, 0), q=yaw(1.0)), "a")
    out = core.lookup_transform_core("world", "robot", rospy.Time(10, 500000000))
    assert out.header.frame_id == "world" and out.child_frame_id == "robot"
    assert (out.header.stamp.secs, out.header.stamp.nsecs) == (10, 500000000)
    assert values(out) == pytest.approx([0.5, 1.0, 0.0, *yaw(0.25)], abs=1e-12)
    # the inverse direction
    back = core.lookup_transform_core("robot", "world", rospy.Time(11))
    x, y, z, *q = values(back)
    assert q == pytest.approx([0.0, 0.0, -math.sin(0.25), math.cos(0.25)], abs=1e-12)
    assert math.hypot(x, y) == pytest.approx(math.hypot(1, 2), abs=1e-12)


def test_time_zero_is_the_latest_common_time_of_the_chain():
    core = BufferCore()
    for s in (10, 11, 12):
        core.set_transform(stamped("world", "base", s, xyz=(s, 0, 0)), "a")
    for s in (10, 11):
        core.set_transform(stamped("base", "arm", s, xyz=(0, s, 0)), "a")
    core.set_transform_static(stamped("arm", "tool", 0, xyz=(0, 0, 1)), "b")
    out = core.lookup_transform_core("world", "tool", rospy.Time())
    assert (out.header.stamp.secs, out.header.stamp.nsecs) == (11, 0)
    assert values(out) == pytest.approx([11, 11, 1, 0, 0, 0, 1])
    assert core.get_latest_common_time("world", "tool") == rospy.Time(11)
    # a chain of static frames only: time 0 everywhere
    out = core.lookup_transform_core("arm", "tool", rospy.Time())
    assert out.header.stamp == rospy.Time(0)


def test_a_single_sample_matches_only_its_own_stamp():
    core = BufferCore()
    core.set_transform(stamped("a", "b", 5), "x")
    assert core.lookup_transform_core("a", "b", rospy.Time(5)).header.stamp == rospy.Time(5)
    with pytest.raises(ExtrapolationException) as err:
        core.lookup_transform_core("a", "b", rospy.Time(6))
    assert str(err.value) == ("Lookup would require extrapolation at time 6.000000000, but only "
                              "time 5.000000000 is in the buffer, when looking up transform "
                              "from frame [b] to frame [a]")


def test_extrapolation_texts_into_the_past_and_the_future():
    core = BufferCore()
    core.set_transform(stamped("a", "b", 10), "x")
    core.set_transform(stamped("a", "b", 11, 500000000), "x")
    with pytest.raises(ExtrapolationException, match=r"^Lookup would require extrapolation "
                       r"0\.500000000s into the future\.  Requested time 12\.000000000 but the "
                       r"latest data is at time 11\.500000000, when looking up transform from "
                       r"frame \[b\] to frame \[a\]$"):
        core.lookup_transform_core("a", "b", rospy.Time(12))
    with pytest.raises(ExtrapolationException, match=r"1\.000000000s into the past\.  Requested "
                       r"time 9\.000000000 but the earliest data is at time 10\.000000000"):
        core.lookup_transform_core("b", "a", rospy.Time(9))


def test_static_frames_are_valid_at_any_time_and_survive_clear():
    core = BufferCore()
    core.set_transform_static(stamped("base", "laser", 3, xyz=(0.2, 0, 0.1)), "urdf")
    for t in (rospy.Time(0), rospy.Time(1), rospy.Time(10 ** 6)):
        out = core.lookup_transform_core("base", "laser", t)
        assert values(out)[:3] == pytest.approx([0.2, 0, 0.1])
        assert out.header.stamp == t
    core.clear()
    assert core.can_transform_core("base", "laser", rospy.Time(7)) == (True, "")


def test_lookup_errors_have_tf2s_classes_and_texts():
    core = BufferCore()
    core.set_transform(stamped("world", "a", 1), "x")
    core.set_transform(stamped("other", "b", 1), "x")
    with pytest.raises(LookupException) as err:
        core.lookup_transform_core("world", "nope", rospy.Time())
    assert str(err.value) == '"nope" passed to lookupTransform argument source_frame does not exist. '
    with pytest.raises(ConnectivityException) as err:
        core.lookup_transform_core("a", "b", rospy.Time())
    assert str(err.value) == ("Could not find a connection between 'a' and 'b' because they are "
                              "not part of the same tree.Tf has two or more unconnected trees.")
    with pytest.raises(InvalidArgumentException) as err:
        core.lookup_transform_core("/world", "a", rospy.Time())
    assert str(err.value) == ('Invalid argument "/world" passed to lookupTransform argument '
                              "target_frame in tf2 frame_ids cannot start with a '/' like: ")
    with pytest.raises(InvalidArgumentException, match="cannot be empty"):
        core.lookup_transform_core("", "a", rospy.Time())
    # all of them are TransformExceptions
    assert issubclass(ExtrapolationException, TransformException)
    # the same frame needs no data, even an unknown one
    assert values(core.lookup_transform_core("nope", "nope", rospy.Time(3))) == [0, 0, 0, 0, 0, 0, 1]


def test_can_transform_reports_why_not():
    core = BufferCore(log=Log())
    core.set_transform(stamped("world", "a", 1), "x")
    assert core.can_transform_core("world", "a", rospy.Time(1)) == (True, "")
    assert core.can_transform_core("x", "y", rospy.Time()) == (
        False, "canTransform: target_frame x does not exist. canTransform: source_frame y does not exist.")
    ok, why = core.can_transform_core("world", "a", rospy.Time(2))
    assert not ok and why.startswith("Lookup would require extrapolation at time 2.000000000")
    # a leading slash: a warning and False, no exception (tf2's canTransform)
    assert core.can_transform_core("/world", "a", rospy.Time()) == (False, "")
    assert "cannot start with a '/'" in core.log.lines[-1][1]


def test_a_cycle_in_the_tree_is_reported_not_looped_forever():
    core = BufferCore(log=Log())
    core.set_transform(stamped("b", "a", 1), "x")
    core.set_transform(stamped("a", "b", 1), "x")
    core.set_transform(stamped("c", "d", 1), "x")
    start = time.monotonic()
    with pytest.raises(LookupException) as err:
        core.lookup_transform_core("d", "a", rospy.Time(1))
    assert str(err.value).startswith("The tf tree is invalid because it contains a loop.\n")
    assert "Frame a exists with parent b." in str(err.value)
    with pytest.raises(TransformException, match="contains a loop"):
        core.lookup_transform_core("d", "a", rospy.Time())  # through the latest common time
    assert core.can_transform_core("d", "a", rospy.Time(1))[0] is False
    assert time.monotonic() - start < 5


def test_insert_checks_refuse_bad_data_with_tf2s_messages():
    log = Log()
    core = BufferCore(log=log)
    assert not core.set_transform(stamped("a", "a", 1), "me")
    assert log.lines[-1] == (logging.ERROR, 'TF_SELF_TRANSFORM: Ignoring transform from authority '
                             '"me" with frame_id and child_frame_id  "a" because they are the same')
    assert not core.set_transform(stamped("a", "b", 1, xyz=(float("nan"), 0, 0)), "me")
    assert log.lines[-1][1].startswith('TF_NAN_INPUT: Ignoring transform for child_frame_id "b" '
                                       'from authority "me" because of a nan value in the '
                                       'transform (nan 0.000000 0.000000)')
    assert not core.set_transform(stamped("a", "b", 1, q=(0, 0, 0, 2)), "me")
    assert "TF_DENORMALIZED_QUATERNION" in log.lines[-1][1]
    assert not core.set_transform(stamped("", "b", 1), "me")
    assert "TF_NO_FRAME_ID" in log.lines[-1][1]
    assert not core.set_transform(stamped("a", "", 1), "me")
    assert any("TF_NO_CHILD_FRAME_ID" in text for _, text in log.lines)
    # nothing was stored
    assert core.all_frames_as_string() == ""
    # slightly denormalised quaternions (within tf2's 1e-2 tolerance) are accepted as they are
    assert core.set_transform(stamped("a", "b", 1, q=(0, 0, 0, 1.004)), "me")
    # one leading slash is stripped on insert
    assert core.set_transform(stamped("/a", "/c", 1), "me")
    assert core.can_transform_core("a", "c", rospy.Time(1)) == (True, "")


def test_repeated_and_old_data_warn_and_are_dropped():
    log = Log()
    core = BufferCore(log=log, warning_interval=0)
    assert core.set_transform(stamped("map", "odom", 100, xyz=(1, 0, 0)), "/loc")
    assert not core.set_transform(stamped("map", "odom", 100, xyz=(2, 0, 0)), "/loc")
    assert log.lines[-1] == (logging.WARNING, "TF_REPEATED_DATA ignoring data with redundant "
                             "timestamp for frame odom (parent map) at time 100.000000 according "
                             "to authority /loc")
    assert values(core.lookup_transform_core("map", "odom", rospy.Time(100)))[0] == 1
    assert not core.set_transform(stamped("map", "odom", 89), "/loc")
    assert log.lines[-1][1] == ("TF_OLD_DATA ignoring data from the past (Possible reasons are "
                                "listed at http://wiki.ros.org/tf/Errors%20explained) for frame "
                                "odom (parent map) at time 89.000000 according to authority /loc")
    # within the cache window, late data is inserted in order
    assert core.set_transform(stamped("map", "odom", 95, xyz=(0, 0, 0)), "/loc")
    assert values(core.lookup_transform_core("map", "odom", rospy.Time(97, 500000000)))[0] == 0.5


def test_insert_warnings_are_rate_limited_per_frame():
    log = Log()
    now = [1000.0]
    core = BufferCore(log=log, warning_interval=10.0, clock=lambda: now[0])
    core.set_transform(stamped("map", "odom", 100), "/loc")
    for _ in range(50):
        core.set_transform(stamped("map", "odom", 100), "/loc")
    assert len(log.lines) == 1
    core.set_transform(stamped("map", "other", 100), "/loc")
    core.set_transform(stamped("map", "other", 100), "/loc")  # another frame: its own report
    assert len(log.lines) == 2
    now[0] += 10.5
    core.set_transform(stamped("map", "odom", 100), "/loc")
    assert len(log.lines) == 3
    assert log.lines[-1][1].endswith("(49 more like this in the last 10 s not shown)")


def test_cache_keeps_cache_time_of_history():
    core = BufferCore(rospy.Duration(2))
    for s in range(10):
        core.set_transform(stamped("a", "b", s), "x")
    cache = core._caches[core._ids["b"]]
    assert cache.stamps == [7 * 10 ** 9, 8 * 10 ** 9, 9 * 10 ** 9]
    with pytest.raises(ExtrapolationException, match="into the past"):
        core.lookup_transform_core("a", "b", rospy.Time(6))


def test_a_parent_change_is_not_interpolated_across():
    core = BufferCore()
    core.set_transform(stamped("p1", "c", 1, xyz=(1, 0, 0)), "x")
    core.set_transform(stamped("p2", "c", 3, xyz=(3, 0, 0)), "x")
    core.set_transform(stamped("p2", "p1", 1), "x")
    core.set_transform(stamped("p2", "p1", 3), "x")
    # between the two samples the older one (parent p1) holds
    out = core.lookup_transform_core("p1", "c", rospy.Time(2))
    assert values(out)[0] == 1


def test_lookup_full_and_chain():
    core = BufferCore()
    core.set_transform(stamped("odom", "base", 1, xyz=(1, 0, 0)), "x")
    core.set_transform(stamped("odom", "base", 2, xyz=(2, 0, 0)), "x")
    core.set_transform_static(stamped("base", "cam", 0, xyz=(0, 0, 1)), "x")
    # where was the camera at t=1, seen from the base at t=2 (odom fixed)?
    out = core.lookup_transform_full_core("base", rospy.Time(2), "cam", rospy.Time(1), "odom")
    assert values(out) == pytest.approx([-1, 0, 1, 0, 0, 0, 1])
    assert out.header.stamp == rospy.Time(2)
    # source to fixed, then fixed to target: Debian's tf2_py lists the same four frames
    assert core._chain("base", rospy.Time(2), "cam", rospy.Time(1), "odom") == [
        "cam", "base", "odom", "base"]
    with pytest.raises(LookupException, match="fixed_frame does not exist"):
        core.lookup_transform_full_core("base", rospy.Time(2), "cam", rospy.Time(1), "nope")


def test_yaml_and_string_views():
    core = BufferCore()
    assert core.all_frames_as_yaml() == "{}"
    core.set_transform(stamped("odom", "base", 1), "/loc")
    core.set_transform(stamped("odom", "base", 3), "/loc")
    core.set_transform_static(stamped("base", "cam", 0), "/urdf")
    assert core.all_frames_as_yaml() == (
        "base: \n  parent: 'odom'\n  broadcaster: '/loc'\n  rate: 1.000\n"
        "  most_recent_transform: 3.000\n  oldest_transform: 1.000\n  buffer_length: 2.000\n"
        "cam: \n  parent: 'base'\n  broadcaster: '/urdf'\n  rate: 10000.000\n"
        "  most_recent_transform: 0.000\n  oldest_transform: 0.000\n  buffer_length: 0.000\n")
    assert core.all_frames_as_string() == ("Frame base exists with parent odom.\n"
                                           "Frame cam exists with parent base.\n")
    dot = core._allFramesAsDot()
    assert dot.startswith("digraph G {\n") and '"odom" -> "base"' in dot and dot.endswith("}")
    assert core._getFrameStrings() == ["base", "odom", "cam"]
    assert core._frameExists("odom") and not core._frameExists("nope")


def test_exact_nanosecond_stamps_are_kept():
    """tf2_py loses ~100 ns through floats on wall-clock stamps; the integer core does not."""
    core = BufferCore()
    core.set_transform(stamped("a", "b", 1700000000, 123456789), "x")
    out = core.lookup_transform_core("a", "b", rospy.Time(1700000000, 123456789))
    assert (out.header.stamp.secs, out.header.stamp.nsecs) == (1700000000, 123456789)


def test_time_arguments():
    core = BufferCore()
    core.set_transform(stamped("a", "b", 2), "x")
    assert core.can_transform_core("a", "b", rospy.Duration(2))[0]  # anything with secs/nsecs
    with pytest.raises(TypeError, match="to_sec"):
        core.lookup_transform_core("a", "b", "now")


def test_a_peer_cannot_grow_a_cache_without_bound(monkeypatch):
    monkeypatch.setattr(tfcore, "MAX_CACHE_LENGTH", 100)
    core = BufferCore()
    for i in range(1000):
        core.set_transform(stamped("a", "b", 0, i * 1000), "x")  # 1 us apart, within 10 s
    assert len(core._caches[core._ids["b"]]) == 100


def test_buffer_waits_for_data_and_wakes_on_insert(monkeypatch):
    import minros

    monkeypatch.setattr(minros, "get_time", time.time)  # ROS time without a node
    buffer = Buffer(debug=False)
    now = rospy.Time.from_sec(time.time())

    def later():
        time.sleep(0.2)
        buffer.set_transform(stamped("map", "robot", now.secs, now.nsecs), "x")

    thread = threading.Thread(target=later, name="inserter")
    start = time.monotonic()
    thread.start()
    out = buffer.lookup_transform("map", "robot", now, rospy.Duration(5))
    waited = time.monotonic() - start
    thread.join()
    assert out.header.stamp == now
    assert 0.15 < waited < 2.0  # woken by the insert, not by the 5 s timeout
    start = time.monotonic()
    assert buffer.can_transform("map", "nope", rospy.Time(), rospy.Duration(0.3)) is False
    assert 0.25 < time.monotonic() - start < 2.0
    ok, why = buffer.can_transform("map", "nope", rospy.Time(), return_debug_tuple=True)
    assert not ok and "nope does not exist" in why
