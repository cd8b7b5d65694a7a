"""topic_tools' decisions without I/O: the throttles, drop and the mux table."""

from __future__ import annotations

import pytest

from minros.topic_tools.policies import ByteThrottle, Dropper, MessageThrottle, MuxTable


def test_message_throttle_keeps_the_minimum_period_and_survives_time_going_back() -> None:
    throttle = MessageThrottle(10.0)
    stamps = [0.0, 0.05, 0.1, 0.15, 0.21, 0.3, 0.32]
    assert [t for t in stamps if throttle.accept(t)] == [0.0, 0.1, 0.21, 0.32]
    # time going back (a restarted bag) starts a new period there, as ROS's throttle does
    assert not throttle.accept(0.01)
    assert throttle.accept(0.12)


def test_byte_throttle_bounds_the_window_average() -> None:
    throttle = ByteThrottle(100.0, 1.0)  # at most 100 bytes in any 1 s window
    assert throttle.accept(0.0, 60)
    assert not throttle.accept(0.5, 60)
    assert throttle.accept(0.6, 40)
    assert throttle.accept(1.2, 60)  # the first 60 bytes left the window
    assert ByteThrottle(10.0, 1.0).accept(0.0, 1000)  # one oversize message still passes


def test_drop_drops_the_first_x_of_every_y() -> None:
    dropper = Dropper(2, 3)
    assert [i for i in range(9) if dropper.accept()] == [2, 5, 8]
    keep_all = Dropper(0, 1)
    assert all(keep_all.accept() for _ in range(5))


@pytest.mark.parametrize("args", [(3, 2), (-1, 2), (1, 0)])
def test_drop_refuses_impossible_ratios(args) -> None:
    with pytest.raises(ValueError, match="0 <= X <= Y"):
        Dropper(*args)


def test_mux_table() -> None:
    table = MuxTable(["/a", "/b", "/a"])
    assert table.topics == ["/a", "/b"] and table.selected == "/a"
    assert table.select("/b") == (True, "/a")
    assert table.select("/c") == (False, "/b") and table.selected == "/b"
    assert table.select("__none") == (True, "/b") and table.selected is None
    assert table.add("/c") and not table.add("/c")
    table.select("/c")
    assert table.delete("/c") and table.selected is None and not table.delete("/c")
    assert MuxTable(["/a", "/b"], "/b").selected == "/b"
    assert MuxTable(["/a"], "__none").selected is None
    with pytest.raises(ValueError, match="initial_topic /z"):
        MuxTable(["/a"], "/z")
