"""The admission policy of minros's servers (minros.wire.admission), without sockets, and the
ROS_ALLOWED_HOSTS rules it applies (minros.rosenv)."""

from __future__ import annotations

import ipaddress
import threading
import time

import pytest

from minros import rosenv
from minros.wire.admission import BUSY, IDLE, READING, Admission, Limits, Refused


class Clock:
    def __init__(self) -> None:
        self.now = 1000.0

    def __call__(self) -> float:
        return self.now


def policy(**limits) -> tuple:
    clock = Clock()
    return Admission(Limits(**limits), clock=clock, what="the master"), clock


# --------------------------------------------------------------------------- the allow-list


def test_allowed_hosts_parsing():
    assert rosenv.allowed_hosts({}) is None
    assert rosenv.allowed_hosts({"ROS_ALLOWED_HOSTS": "  "}) is None
    nets = rosenv.allowed_hosts({"ROS_ALLOWED_HOSTS": "10.0.0.5, 192.168.1.0/24;fe80::1 localhost"})
    assert ipaddress.ip_network("10.0.0.5/32") in nets
    assert ipaddress.ip_network("192.168.1.0/24") in nets
    assert ipaddress.ip_network("fe80::1/128") in nets
    assert ipaddress.ip_network("127.0.0.1/32") in nets  # localhost, resolved
    with pytest.raises(ValueError, match=r"ROS_ALLOWED_HOSTS: \[no.such.host.invalid\] is neither"):
        rosenv.allowed_hosts({"ROS_ALLOWED_HOSTS": "10.0.0.1,no.such.host.invalid"})


def test_host_allowed():
    nets = rosenv.parse_allowed_hosts("10.1.0.0/16")
    assert rosenv.host_allowed("8.8.8.8", None)  # no list: everyone, as in ROS
    assert rosenv.host_allowed("10.1.2.3", nets)
    assert rosenv.host_allowed("::ffff:10.1.2.3", nets)  # IPv4 on a dual-stack socket
    assert not rosenv.host_allowed("10.2.0.1", nets)
    assert rosenv.host_allowed("127.0.0.1", nets) and rosenv.host_allowed("::1", nets)
    assert rosenv.host_allowed("192.168.7.7", nets, local="192.168.7.7")  # this host itself
    assert not rosenv.host_allowed("192.168.7.8", nets, local="192.168.7.7")
    assert not rosenv.host_allowed("not an address", nets)


def test_refusals_name_the_variable_and_are_reported_once_a_minute():
    clock = Clock()
    adm = Admission(allowed=rosenv.parse_allowed_hosts("10.0.0.0/8"), clock=clock,
                    what="/talker")
    with pytest.raises(Refused) as first:
        adm.admit(1, "192.168.0.9")
    assert first.value.status == 403 and first.value.report
    assert str(first.value) == ("connection from 192.168.0.9 refused: not in ROS_ALLOWED_HOSTS "
                                "of /talker")
    for _ in range(50):
        with pytest.raises(Refused) as again:
            adm.admit(2, "192.168.0.9")
        assert not again.value.report
    with pytest.raises(Refused) as other:
        adm.admit(3, "192.168.0.10")
    assert other.value.report  # another peer has its own line
    clock.now += 61
    with pytest.raises(Refused) as later:
        adm.admit(4, "192.168.0.9")
    assert later.value.report
    assert adm.admit(5, "10.3.3.3") == [] and adm.refusals == 53


# --------------------------------------------------------------------------- the cap


def test_full_server_evicts_what_produced_nothing_for_longest():
    adm, clock = policy(max_connections=3, peer_share=1.0)
    adm.admit("served", "127.0.0.1")
    adm.set_state("served", BUSY)
    clock.now += 1
    adm.admit("trickler", "127.0.0.1")
    adm.set_state("trickler", READING)
    clock.now += 1
    adm.admit("idle", "127.0.0.1")
    clock.now += 1
    assert adm.admit("new", "127.0.0.1") == ["trickler"]  # reading since the longest
    assert adm.evicted("trickler") and adm.live() == 3
    clock.now += 1
    assert adm.admit("newer", "127.0.0.1") == ["idle"]
    clock.now += 1
    assert adm.admit("newest", "127.0.0.1") == ["new"]
    adm.set_state("newer", BUSY)
    adm.set_state("newest", BUSY)
    with pytest.raises(Refused, match="the master is serving 3 connections"):
        adm.admit("refused", "127.0.0.1")  # everyone is being served: nothing to close
    for key in ("trickler", "idle", "new", "served"):
        adm.leave(key)
    assert adm.live() == 2


def test_a_full_server_waits_its_grace_for_a_connection_finishing_its_reply():
    # the moment a server's thread has sent its reply and not yet marked its connection idle:
    # a client calling again at once on a new connection must not get "try again"
    adm = Admission(Limits(max_connections=1, peer_share=1.0), what="the master")
    adm.admit("replying", "127.0.0.1")
    adm.set_state("replying", BUSY)
    with pytest.raises(Refused, match="serving 1 connections"):
        adm.admit("impatient", "127.0.0.1")  # no grace: refused, as before
    marked = threading.Timer(0.05, adm.set_state, ("replying", IDLE))
    marked.start()
    try:
        start = time.monotonic()
        assert adm.admit("next call", "127.0.0.1", grace=5.0) == ["replying"]
        assert time.monotonic() - start < 4.0  # woken by the state change, not the grace's end
    finally:
        marked.join()
    adm.set_state("next call", BUSY)
    with pytest.raises(Refused):
        adm.admit("late", "127.0.0.1", grace=0.05)  # nothing became idle: refused after it


def test_at_the_cap_the_peer_holding_most_makes_room():
    adm, clock = policy(max_connections=4, peer_share=1.0)
    adm.admit("remote", "10.0.0.2")  # the oldest, but its peer holds one connection
    for i in range(3):
        clock.now += 1
        adm.admit(f"flood{i}", "10.0.0.66")
    clock.now += 1
    assert adm.admit("more", "10.0.0.66") == ["flood0"]
    assert adm.admit("another", "10.0.0.3") == ["flood1"]


def test_a_peer_over_its_share_closes_its_own_idlest():
    adm, clock = policy(max_connections=8, peer_share=0.5)
    adm.admit("other", "10.0.0.2")
    for i in range(4):
        clock.now += 1
        assert adm.admit(i, "10.0.0.66") == []
    clock.now += 1
    assert adm.admit(4, "10.0.0.66") == [0]  # over its 4, though the server is not full
    for i in (1, 2, 3, 4):
        adm.set_state(i, BUSY)
    assert adm.admit(5, "10.0.0.66") == []  # nothing of its own to close: let in while room


# --------------------------------------------------------------------------- memory


def test_memory_is_charged_as_it_arrives_and_released():
    adm, _ = policy(budget=1000, peer_share=1.0)
    adm.admit("a", "127.0.0.1")
    adm.set_state("a", READING)
    assert adm.charge("a", 600) == [] and adm.held() == 600
    adm.release("a")
    assert adm.held() == 0
    adm.charge("a", 10)
    adm.leave("a")
    assert adm.held() == 0


def test_a_full_budget_closes_older_unfinished_requests_first():
    adm, clock = policy(budget=1000, peer_share=1.0)
    for key in ("slow1", "slow2", "honest"):
        adm.admit(key, "127.0.0.1")
        adm.set_state(key, READING)
        clock.now += 1
    adm.charge("slow1", 450)
    adm.charge("slow2", 450)
    assert adm.charge("honest", 300) == ["slow1"]  # enough room after one
    assert adm.held() == 750
    with pytest.raises(Refused, match="busy with large requests"):
        adm.charge("slow2", 400)  # a newer one never closes an older one for itself
    adm.set_state("slow2", BUSY)
    with pytest.raises(Refused):
        adm.charge("honest", 400)  # a request being served is never closed
    with pytest.raises(Refused, match="closed to make room"):
        adm.charge("slow1", 1)


def test_one_peer_holds_at_most_its_share_of_the_budget():
    adm, clock = policy(budget=1000, peer_share=0.5)
    for key, peer in (("a", "10.0.0.66"), ("b", "10.0.0.66"), ("c", "10.0.0.2")):
        adm.admit(key, peer)
        adm.set_state(key, READING)
        clock.now += 1
    adm.charge("a", 400)
    assert adm.charge("b", 300) == ["a"]  # its own older request makes room
    with pytest.raises(Refused, match="requests from 10.0.0.66 hold 500 bytes"):
        adm.charge("b", 300)
    assert adm.charge("c", 500) == []  # the other peer still has its share


def test_deadlines_are_fixed_by_the_announced_length():
    limits = Limits(head_timeout=10.0, min_rate=1000.0)
    assert limits.body_deadline(100.0, 0) == 110.0
    assert limits.body_deadline(100.0, 5000) == 115.0
    assert limits.transfer_time(2000) == 12.0
    assert Limits(max_connections=10, peer_share=0.01).peer_connections == 1
