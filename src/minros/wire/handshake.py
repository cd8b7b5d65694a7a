"""The TCPROS connection-header exchange as one state machine, without I/O (as h11's _state.py).

Every TCPROS connection opens with an exchange of connection headers. Who speaks first, what
each side checks, and what the connection is afterwards depend on its kind, and this module
writes all of it down once; the code that owns a socket only moves the bytes it is given
(``minros.transport.tcpros_base.negotiate``)::

    topic     subscriber --{topic, md5sum, type, callerid, ...}--> publisher
              subscriber <--{type, md5sum, latching, ...} | {error}-- publisher
              then message frames, publisher -> subscriber only
    service   client --{service, md5sum, callerid[, persistent][, probe]}--> server
              client <--{service, type, md5sum, callerid} | {error}-- server
              then request/response frames (many when persistent); a probe ends here

One :class:`Handshake` is one side's view. The initiator (``SUBSCRIBER``, ``SERVICE_CLIENT``)
sends :meth:`Handshake.opening`, then hands the peer's answer to :meth:`Handshake.reply_received`;
the acceptor (``PUBLISHER``, ``SERVICE_SERVER``) hands the opening it read to
:meth:`Handshake.opening_received` and sends what that returns. The states::

    initiator  IDLE --opening()--> AWAIT_REPLY --reply_received()--> OPEN | REJECTED
               IDLE --opening()--> CLOSED                    (a probe: the answer is not read)
    acceptor   IDLE --opening_received()--> OPEN | CLOSED | REJECTED

OPEN carries frames; CLOSED is a probe (nothing follows its headers); REJECTED is a
refusal, in either direction (the acceptor sent ``error=...``, or the initiator found the
answer wrong), and raises :class:`Rejected` with the text rospy uses. Calling a method in the
wrong state is a bug of the caller and raises :class:`HandshakeStateError`.
"""

from __future__ import annotations

import enum
from typing import Dict, Mapping

from minros.exceptions import TransportInitError
from minros.wire import tcpros

__all__ = ["Handshake", "HandshakeStateError", "Rejected", "Role", "State", "refusal", "route"]


class Role(enum.Enum):
    SUBSCRIBER = "subscriber"
    PUBLISHER = "publisher"
    SERVICE_CLIENT = "service client"
    SERVICE_SERVER = "service server"

    @property
    def initiates(self) -> bool:
        """Whether this side sends the first header."""
        return self in (Role.SUBSCRIBER, Role.SERVICE_CLIENT)


class State(enum.Enum):
    IDLE = "idle"
    AWAIT_REPLY = "await reply"
    OPEN = "open"
    CLOSED = "closed"
    REJECTED = "rejected"


class Rejected(TransportInitError):
    """The exchange refused the connection; ``str()`` is the reason (rospy's words)."""


class HandshakeStateError(RuntimeError):
    """A Handshake method called in a state where it has no meaning (a bug of the caller)."""


def route(header: Mapping[str, str]) -> str | None:
    """What an inbound connection's opening header asks for: "topic", "service", or None."""
    if "topic" in header:
        return "topic"
    if "service" in header:
        return "service"
    return None


def refusal(text: str) -> bytes:
    """The answer to an opening nothing here can serve (an unknown topic or service)."""
    return tcpros.encode_error_header(text)


class Handshake:
    """One side of one connection-header exchange.

    ``ours`` are this side's header fields: the initiator sends them, the acceptor answers
    with them, and both sides check the peer against them (``topic``/``service``, ``type``,
    ``md5sum``, ``callerid``). ``refuse`` is an acceptor's own reason to refuse whatever
    comes (a closed publication, a service shutting down), answered after the peer's header
    was found valid, as rospy answers.
    """

    __slots__ = ("role", "ours", "refuse", "state", "peer", "error")

    def __init__(self, role: Role, ours: Mapping[str, str], refuse: str | None = None) -> None:
        self.role = role
        self.ours: Dict[str, str] = dict(ours)
        self.refuse = refuse
        self.state = State.IDLE
        #: the peer's header, once received
        self.peer: Dict[str, str] = {}
        #: why the connection was refused (REJECTED)
        self.error: str | None = None

    # -- initiator ---------------------------------------------------------------------------

    def opening(self) -> bytes:
        """The initiator's header, to send first (a probe is over once it is sent)."""
        self._expect(State.IDLE, initiator=True)
        self.state = State.CLOSED if self.probe else State.AWAIT_REPLY
        return tcpros.encode_header(self.ours)

    def reply_received(self, header: Mapping[str, str]) -> None:
        """The acceptor's answer: OPEN, or Rejected if it refused or does not match."""
        self._expect(State.AWAIT_REPLY, initiator=True)
        self.peer = dict(header)
        if self.role is Role.SUBSCRIBER:
            ours = self.ours
            error = tcpros.subscriber_header_error(header, ours["topic"], ours["md5sum"],
                                                   ours["type"])
        else:
            error = _service_reply_error(header)
        if error is not None:
            self._reject(error)
        self.state = State.OPEN

    # -- acceptor ----------------------------------------------------------------------------

    def opening_received(self, header: Mapping[str, str]) -> bytes:
        """The initiator's header: the bytes to answer with (ours, or ``error=`` when it does
        not match or the acceptor refuses). The state is OPEN, CLOSED (a probe) or REJECTED
        afterwards; nothing is raised."""
        self._expect(State.IDLE, initiator=False)
        self.peer = dict(header)
        ours = self.ours
        if self.role is Role.PUBLISHER:
            topic = ours["topic"]
            error = tcpros.publisher_header_error(header, ours["callerid"],
                                                  {topic: (ours["type"], ours["md5sum"])})
        else:
            error = tcpros.service_header_error(header, ours["service"], ours["md5sum"])
        if error is None:
            error = self.refuse
        if error is not None:
            self.state = State.REJECTED
            self.error = error
            return tcpros.encode_error_header(error)
        self.state = State.CLOSED if self.probe else State.OPEN
        return tcpros.encode_header(ours)

    # -- what the connection is --------------------------------------------------------------

    @property
    def probe(self) -> bool:
        """A service probe (wait_for_service): the exchange is all there is."""
        if self.role is Role.SERVICE_CLIENT:
            return self.ours.get("probe") == "1"
        return self.role is Role.SERVICE_SERVER and self.peer.get("probe") == "1"

    @property
    def persistent(self) -> bool:
        """A service connection that carries more than one request."""
        side = self.ours if self.role is Role.SERVICE_CLIENT else self.peer
        return side.get("persistent", "").lower() in ("1", "true")

    @property
    def latching(self) -> bool:
        """The publisher latches: its last message comes first."""
        side = self.peer if self.role is Role.SUBSCRIBER else self.ours
        return side.get("latching", "0") == "1"

    def tcp_nodelay(self, default: bool) -> bool:
        """Publisher: whether the subscriber asked for TCP_NODELAY (``default`` if it did not say)."""
        if "tcp_nodelay" not in self.peer:
            return default
        return self.peer["tcp_nodelay"].strip() == "1"

    # -- internals ---------------------------------------------------------------------------

    def _expect(self, state: State, initiator: bool) -> None:
        if self.role.initiates != initiator:
            raise HandshakeStateError(f"a {self.role.value} does not "
                                      f"{'send' if initiator else 'receive'} the first header")
        if self.state is not state:
            raise HandshakeStateError(f"{self.role.value} handshake is {self.state.value}, "
                                      f"not {state.value}")

    def _reject(self, error: str) -> None:
        self.state = State.REJECTED
        self.error = error
        raise Rejected(error)


def _service_reply_error(header: Mapping[str, str]) -> str | None:
    """A service server's answer as rospy's client checks it."""
    if "error" in header:
        return f"remote error reported: {header['error']}"
    for required in ("md5sum", "type"):
        if required not in header:
            return f"header missing required field [{required}]"
    return None
