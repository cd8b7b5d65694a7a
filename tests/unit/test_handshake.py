"""The connection-header exchange as a state machine (wire/handshake.py), without I/O: who
sends first, what each side checks, what the connection is afterwards, rospy's error texts."""

from __future__ import annotations

import pytest

from minros.wire import tcpros
from minros.wire.handshake import Handshake, HandshakeStateError, Rejected, Role, State, route

STRING_MD5 = "992ce8a1687cec8c8bd883ec73ca41d1"

SUBSCRIBER = {"topic": "/chatter", "md5sum": STRING_MD5, "type": "std_msgs/String",
              "callerid": "/listener", "message_definition": "string data\n", "tcp_nodelay": "1"}
PUBLISHER = {"topic": "/chatter", "md5sum": STRING_MD5, "type": "std_msgs/String",
             "callerid": "/talker", "latching": "1", "message_definition": "string data\n"}


def decode(block: bytes) -> dict:
    fields, used = tcpros.read_header_block(block)
    assert used == len(block)
    return fields


def exchange(initiator: Handshake, acceptor: Handshake) -> bytes:
    """Both sides of one exchange, bytes through the codec as on the wire; the acceptor's answer."""
    answer = acceptor.opening_received(decode(initiator.opening()))
    if initiator.state is State.AWAIT_REPLY:
        initiator.reply_received(decode(answer))
    return answer


def test_a_topic_connection_opens_on_both_sides():
    sub, pub = Handshake(Role.SUBSCRIBER, SUBSCRIBER), Handshake(Role.PUBLISHER, PUBLISHER)
    assert sub.state is pub.state is State.IDLE
    exchange(sub, pub)
    assert sub.state is pub.state is State.OPEN
    assert sub.peer == PUBLISHER and pub.peer == SUBSCRIBER
    assert sub.latching and pub.latching
    assert pub.tcp_nodelay(default=False) is True


def test_the_publisher_refuses_a_wrong_md5_and_the_subscriber_reads_why():
    wrong = dict(SUBSCRIBER, md5sum="0" * 32)
    sub, pub = Handshake(Role.SUBSCRIBER, wrong), Handshake(Role.PUBLISHER, PUBLISHER)
    with pytest.raises(Rejected) as refused:
        exchange(sub, pub)
    assert pub.state is sub.state is State.REJECTED
    assert pub.error == ("Client [/listener] wants topic [/chatter] to have datatype/md5sum "
                         f"[std_msgs/String/{'0' * 32}], but our version has "
                         f"[std_msgs/String/{STRING_MD5}] Dropping connection.")
    assert str(refused.value) == f"remote error reported: {pub.error}"


def test_the_subscriber_checks_the_publisher_too():
    sub = Handshake(Role.SUBSCRIBER, SUBSCRIBER)
    sub.opening()
    with pytest.raises(Rejected, match=r"md5sum mismatch on topic \[/chatter\]"):
        sub.reply_received(dict(PUBLISHER, md5sum="f" * 32))
    sub = Handshake(Role.SUBSCRIBER, SUBSCRIBER)
    sub.opening()
    with pytest.raises(Rejected, match=r"header missing required field \[type\]"):
        sub.reply_received({"md5sum": STRING_MD5})


def test_an_acceptor_may_refuse_a_valid_opening_for_its_own_reason():
    pub = Handshake(Role.PUBLISHER, PUBLISHER, refuse="Internal error processing topic [/chatter]")
    answer = pub.opening_received(SUBSCRIBER)
    assert pub.state is State.REJECTED
    assert decode(answer) == {"error": "Internal error processing topic [/chatter]"}
    # the header's own fault is named first
    pub = Handshake(Role.PUBLISHER, PUBLISHER, refuse="shutting down")
    assert decode(pub.opening_received({"topic": "/chatter"})) == {
        "error": "Missing required 'md5sum' field"}


SERVER = {"service": "/add", "md5sum": "6a2e34150c00229791cc89ff309fff21",
          "type": "rospy_tutorials/AddTwoInts", "callerid": "/server"}


def test_a_service_connection_is_persistent_when_the_client_asks():
    client = Handshake(Role.SERVICE_CLIENT, {"service": "/add", "md5sum": "*",
                                             "callerid": "/client", "persistent": "1"})
    server = Handshake(Role.SERVICE_SERVER, SERVER)
    exchange(client, server)
    assert client.state is server.state is State.OPEN
    assert client.persistent and server.persistent
    one_shot = Handshake(Role.SERVICE_SERVER, SERVER)
    one_shot.opening_received({"service": "/add", "md5sum": "*", "callerid": "/c"})
    assert not one_shot.persistent


def test_a_probe_ends_with_the_headers():
    client = Handshake(Role.SERVICE_CLIENT, {"service": "/add", "md5sum": "*",
                                             "callerid": "/c", "probe": "1"})
    opening = client.opening()
    assert client.state is State.CLOSED  # wait_for_service does not read the answer
    server = Handshake(Role.SERVICE_SERVER, SERVER)
    assert decode(server.opening_received(decode(opening))) == SERVER
    assert server.state is State.CLOSED and server.probe


def test_service_refusals_name_the_mismatch():
    server = Handshake(Role.SERVICE_SERVER, SERVER)
    answer = server.opening_received({"service": "/other", "md5sum": "*", "callerid": "/c"})
    assert decode(answer) == {"error": "request from [/c]: service name does not match: "
                                        "[/other] vs. [/add]"}
    client = Handshake(Role.SERVICE_CLIENT, {"service": "/add", "md5sum": "*", "callerid": "/c"})
    client.opening()
    with pytest.raises(Rejected, match=r"^remote error reported: gone$"):
        client.reply_received({"error": "gone"})


def test_calls_out_of_turn_are_the_callers_bug():
    sub = Handshake(Role.SUBSCRIBER, SUBSCRIBER)
    with pytest.raises(HandshakeStateError, match="not await reply"):
        sub.reply_received(PUBLISHER)
    with pytest.raises(HandshakeStateError, match="does not receive the first header"):
        sub.opening_received(PUBLISHER)
    sub.opening()
    with pytest.raises(HandshakeStateError):
        sub.opening()
    pub = Handshake(Role.PUBLISHER, PUBLISHER)
    with pytest.raises(HandshakeStateError, match="does not send the first header"):
        pub.opening()


def test_route_names_what_an_inbound_header_asks_for():
    assert route({"topic": "/a", "md5sum": "*"}) == "topic"
    assert route({"service": "/s"}) == "service"
    assert route({"callerid": "/x"}) is None
