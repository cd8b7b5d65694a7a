"""The ROS environment rules that every node and tool shares (minros.rosenv)."""

from __future__ import annotations

from pathlib import Path

from minros import rosenv


def test_master_uri_precedence():
    assert rosenv.get_master_uri({}) == "http://localhost:11311/"
    assert rosenv.get_master_uri({"ROS_MASTER_URI": "http://h:1/"}) == "http://h:1/"
    assert rosenv.get_master_uri({"ROS_MASTER_URI": "http://h:1/"}, remapped="http://r:2/") == "http://r:2/"
    assert rosenv.get_master_uri({"ROS_MASTER_URI": ""}) == rosenv.DEFAULT_MASTER_URI


def test_ros_home_and_log_dir_defaults():
    assert rosenv.ros_home({"HOME": "/u"}) == Path("/u/.ros")
    assert rosenv.ros_home({"HOME": "/u", "ROS_HOME": "/rh"}) == Path("/rh")
    assert rosenv.ros_log_dir({"HOME": "/u"}) == Path("/u/.ros/log")
    assert rosenv.ros_log_dir({"ROS_HOME": "/rh"}) == Path("/rh/log")
    assert rosenv.ros_log_dir({"ROS_HOME": "/rh", "ROS_LOG_DIR": "/logs"}) == Path("/logs")
