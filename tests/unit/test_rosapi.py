"""The ROS API convention (wire/rosapi) and the address rules nodes advertise (rosenv)."""

from __future__ import annotations

import pytest

from minros import rosenv
from minros.wire import rosapi


def test_triplets_and_unwrap():
    assert rosapi.triplet(rosapi.SUCCESS, "", 3) == [1, "", 3]
    assert rosapi.unwrap([1, "ok", 5]) == 5
    with pytest.raises(rosapi.CallerError) as info:
        rosapi.unwrap([-1, "no such node", ""])
    assert info.value.code == rosapi.ERROR and info.value.msg == "no such node"
    with pytest.raises(rosapi.CalleeFailure) as failed:
        rosapi.unwrap([0, "internal", 0])
    assert failed.value.code == rosapi.FAILURE and isinstance(failed.value, rosapi.RemoteError)
    with pytest.raises(rosapi.CalleeFailure, match="malformed"):
        rosapi.unwrap("nonsense")


def test_address_rules():
    assert rosenv.get_bind_address(env={"ROS_HOSTNAME": "localhost"}) == "127.0.0.1"
    assert rosenv.get_bind_address(env={"ROS_IP": "127.0.0.5"}) == "127.0.0.5"
    assert rosenv.get_bind_address(env={"ROS_IP": "10.1.2.3"}) == "0.0.0.0"
    assert rosenv.get_bind_address(env={"ROS_HOSTNAME": "localhost", "ROS_IPV6": "on"}) == "::1"
    assert rosenv.get_address_override({"ROS_IP": "1.2.3.4", "ROS_HOSTNAME": "h"}, []) == "h"
    assert rosenv.get_address_override({"ROS_IP": "1.2.3.4"}, ["__ip:=5.6.7.8"]) == "5.6.7.8"
    assert rosenv.create_local_xmlrpc_uri(1234, {"ROS_HOSTNAME": "h"}) == "http://h:1234/"
