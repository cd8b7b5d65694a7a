"""tf2_web_republisher's send decision (TFPair), without sockets."""

from __future__ import annotations

import math

from minros.tf2_web_republisher.pairs import TFPair, clean_frame, rotation_angle

IDENTITY = (0.0, 0.0, 0.0, 1.0)


def test_first_update_is_sent_then_only_moves_past_a_threshold() -> None:
    pair = TFPair("/arm", "base", angular_thres=0.1, trans_thres=0.5)
    assert (pair.source_frame, pair.target_frame) == ("arm", "base")
    assert not pair.update_needed()  # nothing received yet
    pair.update((0.0, 0.0, 0.0), IDENTITY)
    assert pair.update_needed()
    pair.transmitted_now()
    pair.update((0.3, 0.0, 0.0), IDENTITY)
    assert not pair.update_needed()
    pair.update((0.6, 0.0, 0.0), IDENTITY)
    assert pair.update_needed()
    pair.transmitted_now()
    assert not pair.update_needed()  # no new update since
    half = math.sin(0.15)  # a rotation of 0.3 rad: tf's angle() is half of it, 0.15 > 0.1
    pair.update((0.6, 0.0, 0.0), (0.0, 0.0, half, math.cos(0.15)))
    assert pair.update_needed()


def test_a_zero_threshold_sends_every_update() -> None:
    pair = TFPair("a", "b", angular_thres=0.0, trans_thres=1.0)
    for _ in range(3):
        pair.update((0.0, 0.0, 0.0), IDENTITY)
        assert pair.update_needed()
        pair.transmitted_now()


def test_helpers() -> None:
    assert clean_frame("/map") == "map" and clean_frame("map") == "map"
    assert rotation_angle(IDENTITY, IDENTITY) == 0.0
    assert rotation_angle((0, 0, 0, 0), IDENTITY) == 0.0
