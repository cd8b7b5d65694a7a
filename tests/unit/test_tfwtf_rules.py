"""tf.tfwtf's rules over heard /tf messages: re-parenting, cycles, two publishers of one
frame, stamps far from ROS time, non-unit rotations."""

from __future__ import annotations

import pytest

from geometry_msgs.msg import TransformStamped
from minros.cli import tfwtf
from minros.cli.wtf import WtfContext
from minros.msgs import Time
from tf2_msgs.msg import TFMessage


def _tf(parent: str, child: str, stamp: float = 10.0, w: float = 1.0) -> TransformStamped:
    t = TransformStamped()
    t.header.frame_id, t.child_frame_id = parent, child
    t.header.stamp = Time.from_sec(stamp)
    t.transform.rotation.w = w
    return t


@pytest.fixture
def heard(monkeypatch: pytest.MonkeyPatch) -> list:
    msgs: list = []
    monkeypatch.setattr(tfwtf, "_msgs", msgs)
    return msgs


def test_rules_find_each_fault(heard: list) -> None:
    ctx = WtfContext()
    assert tfwtf.no_msgs(ctx)
    now = Time.from_sec(10.0)
    heard.append((TFMessage([_tf("map", "odom"), _tf("odom", "base")]), now, "/a"))
    heard.append((TFMessage([_tf("world", "odom", stamp=14.5)]), now, "/b"))
    heard.append((TFMessage([_tf("base", "map", w=0.5)]), now, "/a"))
    assert not tfwtf.no_msgs(ctx)
    assert tfwtf.reparenting(ctx) == ["reparenting of [odom] to [world] by [/b]"]
    assert tfwtf.multiple_authority(ctx) == [
        "node [/b] publishing transform [odom] with parent [world] already published by node [/a]"]
    assert tfwtf.rostime_delta(ctx) == [
        "receiving transform from [/b] that differed from ROS time by 4.5s"]
    assert tfwtf.not_normalized(ctx) == ["rotation from [base] to [map] is not unit length, 0.5"]
    assert tfwtf.cycle_detection(ctx) == []  # base -> odom -> world: odom's parent was replaced
    heard.append((TFMessage([_tf("base", "odom")]), now, "/a"))
    assert any(c.startswith("Frame odom is in a loop") for c in tfwtf.cycle_detection(ctx))
    for rule in tfwtf.tf_errors:
        tfwtf.error_rule(rule, rule[0](ctx), ctx)
    assert ctx.errors[0].msg.startswith("TF re-parenting contention:\n * reparenting of [odom]")


def test_plugin_does_nothing_without_a_tf_publisher(heard: list, monkeypatch) -> None:
    monkeypatch.setattr(tfwtf, "is_tf_active", lambda master_uri=None: False)
    ctx = WtfContext()
    tfwtf.roswtf_plugin_online(ctx)
    assert ctx.warnings == [] and ctx.errors == []
