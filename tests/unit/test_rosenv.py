"""The ROS environment rules that every node and tool shares (minros.rosenv)."""

from __future__ import annotations

from pathlib import Path

import pytest

from minros import rosenv
from minros.exceptions import ROSInitException


def test_master_uri_precedence():
    assert rosenv.get_master_uri({}) == "http://localhost:11311/"
    assert rosenv.get_master_uri({"ROS_MASTER_URI": "http://h:1/"}) == "http://h:1/"
    assert rosenv.get_master_uri({"ROS_MASTER_URI": "http://h:1/"}, remapped="http://r:2/") == "http://r:2/"
    assert rosenv.get_master_uri({"ROS_MASTER_URI": ""}) == rosenv.DEFAULT_MASTER_URI


def test_a_master_uri_that_is_no_uri_is_named_with_its_fix():
    """ROS_MASTER_URI=localhost:11311 (no scheme) is the classic first-day mistake: every
    reader of the URI says which value is wrong and what to set instead."""
    with pytest.raises(rosenv.MasterURIError) as caught:
        rosenv.get_master_uri({"ROS_MASTER_URI": "localhost:11311"})
    assert str(caught.value) == ("ROS_MASTER_URI is 'localhost:11311', which is not a master "
                                 "URI (it lacks the scheme http://): set "
                                 "ROS_MASTER_URI=http://localhost:11311")
    assert isinstance(caught.value, ValueError)  # what rosgraph raises for it
    assert isinstance(caught.value, ROSInitException)  # what init_node raises
    with pytest.raises(rosenv.MasterURIError, match=r"use __master:=http://h:2$"):
        rosenv.get_master_uri({}, remapped="h:2")
    for bad, fix in (("ftp://h:1", "http://h:1"), ("http://h:99999", "http://HOST:PORT"),
                     ("http://", "http://HOST:PORT"), ("h", "http://h")):
        with pytest.raises(rosenv.MasterURIError, match=f"set ROS_MASTER_URI={fix}"):
            rosenv.get_master_uri({"ROS_MASTER_URI": bad})
    # roswtf reads it unchecked, to report it among its findings
    assert rosenv.get_master_uri({"ROS_MASTER_URI": "h:1"}, check=False) == "h:1"
    for good in ("http://h", "https://h:1/", "http://[::1]:11311/", "http://10.0.0.2:11311"):
        assert rosenv.get_master_uri({"ROS_MASTER_URI": good}) == good


def test_ros_home_and_log_dir_defaults():
    assert rosenv.ros_home({"HOME": "/u"}) == Path("/u/.ros")
    assert rosenv.ros_home({"HOME": "/u", "ROS_HOME": "/rh"}) == Path("/rh")
    assert rosenv.ros_log_dir({"HOME": "/u"}) == Path("/u/.ros/log")
    assert rosenv.ros_log_dir({"ROS_HOME": "/rh"}) == Path("/rh/log")
    assert rosenv.ros_log_dir({"ROS_HOME": "/rh", "ROS_LOG_DIR": "/logs"}) == Path("/logs")
