"""rosout.log formatting, rotation and the log directory rules (no ROS needed)."""

from __future__ import annotations

from types import SimpleNamespace

from minros.nodes.rosout import format_line
from minros.rosenv import ros_log_dir as log_dir


def _msg(level=2, topics=("/rosout", "/chatter")):
    return SimpleNamespace(header=SimpleNamespace(stamp=SimpleNamespace(secs=1700000000, nsecs=42)),
                           level=level, name="/talker", file="talker.py", line=12,
                           function="main", topics=list(topics), msg="hello world")


def test_line_format_matches_cpp_rosout():
    assert format_line(_msg()) == ("1700000000.000000042 INFO /talker [talker.py:12(main)] "
                                   "[topics: /rosout, /chatter] hello world\n")
    assert " FATAL " in format_line(_msg(level=16))
    assert " 3 " in format_line(_msg(level=3))  # unknown levels print their number
    assert "[topics: ]" in format_line(_msg(topics=()))


def test_log_dir_rules(tmp_path):
    assert log_dir({"ROS_LOG_DIR": "/x/y", "ROS_HOME": "/h"}) == tmp_path.__class__("/x/y")
    assert str(log_dir({"ROS_HOME": "/h"})) == "/h/log"
    assert str(log_dir({})).endswith(".ros/log")
