"""The transport seam: one interface for a topic connection, one for a protocol (rospy's
impl/transport.py).

A :class:`Transport` is one end of one topic connection, whatever carries it: it negotiates
(its side of the connection-header exchange), sends frames (the publisher's end), receives
frames (the subscriber's end) and closes. A frame is what ``serialize_frame`` makes: a
serialized message with its 4-byte length prefix, as ``bytes`` or, for a big message, a tuple
of buffers, the prefix at the start of the first.

A transport also says what else it can do for a publication, with defaults every other
transport inherits, so the publication needs to know no protocol: ``takes_objects``/``put``
(an intra-process link hands over the message object itself), ``lend``/``give_back``/
``send_loaned`` (shared memory lends a slot for a message's large array, so publishing copies
nothing), ``release`` (a subscriber's end whose frames borrow its buffers gives them back).

A :class:`ProtocolHandler` is one protocol a node speaks: what a subscriber offers in
``requestTopic`` and how it connects to what the publisher chose; what a publisher answers to
an offer; and which inbound connections it takes (the node has one inbound server; each of its
listening sockets, TCP or abstract Unix, is named by the protocol it serves). A node keeps an
ordered list of them (:attr:`minros.node.Node.protocols`: a subscriber offers them in that
order, TCPROS last), so another transport joins by adding its handler there; the topic API
(``minros.client``) only ever sees ``Transport``.

A transport that cannot carry a connection after all (shared memory refused by the kernel, a
peer breaking the protocol) raises :class:`FallBack`: the subscriber logs it once and asks the
publisher again without offering that protocol, so the connection ends up on TCPROS.
"""

from __future__ import annotations

import abc
import itertools
import threading
from typing import Any, Callable, Dict, List, Protocol, Tuple, Union

from minros.exceptions import TransportException
from minros.msgs import reader_for
from minros.wire.handshake import Handshake

__all__ = ["FallBack", "Frame", "ProtocolHandler", "PublicationSide", "Transport",
           "next_connection_id", "subscriber_header"]

#: a length-prefixed message: bytes, or a tuple of buffers (prefix first) sent without a join
Frame = Union[bytes, Tuple[Any, ...]]

_ids = itertools.count(1)
_ids_lock = threading.Lock()


class FallBack(TransportException):
    """This protocol cannot carry the connection (the reason is the text): connect again with
    the next protocol the node speaks. ``protocol`` names the one that failed, once known."""

    protocol = ""


def next_connection_id() -> int:
    """A process-wide connection number (getBusInfo/getBusStats identify connections by it)."""
    with _ids_lock:
        return next(_ids)


class Transport(abc.ABC):
    """One end of one topic connection.

    Attributes every transport keeps (getBusInfo and getBusStats read them): ``id``;
    ``header``, the peer's connection header once negotiated; ``stat_bytes`` and ``stat_msgs``;
    ``done``, true once closed.
    """

    #: the protocol name, as in requestTopic (``"TCPROS"``)
    protocol = ""

    id: int
    header: Dict[str, str]
    stat_msgs: int
    done: bool

    @property
    @abc.abstractmethod
    def stat_bytes(self) -> int:
        """Bytes sent (the publisher's end) or received (the subscriber's end)."""

    @abc.abstractmethod
    def negotiate(self, handshake: Handshake, opening: Dict[str, str] | None = None) -> None:
        """Run this end's side of the connection-header exchange (``opening``: the peer's
        header, when the acceptor has read it already); raises ``Rejected`` or
        TransportException."""

    def send(self, frame: Frame) -> None:
        """Send one frame to the peer (the publisher's end). A queued publisher does not
        wait for a slow subscriber (at most a big frame's send time, a few milliseconds,
        when the queue is full); the oldest queued frame is dropped when the queue is full."""
        raise TransportException(f"this end of a {self.protocol} connection does not send")

    def receive(self) -> List[Any] | None:
        """Block until the peer sends more; the frames it completed (perhaps none yet), or
        None at a clean end of the stream (the subscriber's end). Frames are ``bytes`` or,
        when large, a ``bytearray`` of their own that message fields may keep views of."""
        raise TransportException(f"this end of a {self.protocol} connection does not receive")

    def message_reader(self, data_class: Any) -> Callable[[Any], Any]:
        """The function from this end's received frames to new ``data_class`` messages."""
        read: Callable[[Any], Any] = reader_for(data_class)
        return read

    #: None, or called with each message after its callbacks ran, before the next
    #: ``receive``: a transport whose messages borrow its buffers makes a message that the
    #: callbacks kept its own here (shared memory)
    settle: Callable[[Any], None] | None = None

    def release(self) -> None:  # noqa: B027 - most transports lend nothing
        """The subscriber is done with the frames of the last ``receive``: a transport whose
        frames borrow its buffers may reuse them now (``receive`` does this itself first; a
        reader that waits for the stream to be readable before receiving calls it)."""

    # -- what a publication may ask of a connection (the defaults: frames only) -------------

    #: the publication hands this end message objects (``put``), not frames
    takes_objects = False

    def put(self, msg: Any) -> None:
        """Hand over the message object itself (a transport that ``takes_objects``)."""
        raise TransportException(f"a {self.protocol} connection takes frames, not objects")

    def lend(self, nbytes: int) -> Any:
        """Memory for a message's large array of ``nbytes`` that this connection can send
        without a copy (an object with a writable ``view``), or None (the default)."""
        return None

    def give_back(self, loan: Any) -> None:  # noqa: B027 - nothing is lent by default
        """A loan of :meth:`lend` not published after all."""

    def send_loaned(self, loan: Any, head: bytes, tail: bytes) -> bool:
        """Send the message whose array is ``loan``'s memory (``head``: its frame up to the
        array, length prefix included; ``tail``: the rest). False when it cannot (the caller
        sends the frame as usual)."""
        return False

    @abc.abstractmethod
    def close(self) -> None:
        """End the connection (idempotent); a thread blocked in send or receive wakes up."""

    @abc.abstractmethod
    def info(self) -> str:
        """One line for getBusInfo, as rospy writes it."""

    # rospy's names (rospy.impl.transport.Transport, whose classes are transports here too)

    @property
    def endpoint_id(self) -> str:
        """Who is at the other end: the peer's caller id, from its header."""
        return self.header.get("callerid", "")

    @property
    def transport_type(self) -> str:
        """The protocol's name, as getBusInfo lists it."""
        return self.protocol


class PublicationSide(Protocol):
    """What a protocol handler needs of a publication to connect a subscriber to it."""

    resolved_name: str
    type: str
    md5sum: str
    data_class: Any
    queue_size: int | None
    tcp_nodelay: bool
    #: whether subscribers in this process get the published objects themselves
    intraprocess: bool
    closed: bool

    def header_fields(self) -> Dict[str, str]: ...
    def add_connection(self, transport: Transport) -> bool: ...
    def remove_connection(self, transport: Transport) -> None: ...


class ProtocolHandler(abc.ABC):
    """A protocol a node speaks (rospy's ProtocolHandler)."""

    #: the protocol name in requestTopic
    protocol = ""

    def offer(self) -> List[Any]:
        """The subscriber's entry in requestTopic's protocol list (``[name, params...]``)."""
        return [self.protocol]

    @abc.abstractmethod
    def answer(self, topic: str, offer: List[Any]) -> List[Any] | None:
        """The publisher's answer to a subscriber's ``offer`` of this protocol
        (``[name, params...]``), or None to decline it."""

    @abc.abstractmethod
    def connect(self, answer: List[Any], topic: str, buff_size: int, reuse_big: bool,
                tcp_nodelay: bool) -> Transport:
        """The subscriber's end of a connection to the publisher that gave ``answer``,
        connected but not negotiated yet (the caller may close it meanwhile). ValueError for
        an answer this handler cannot use; OSError when the publisher cannot be reached.
        ``reuse_big``: the subscriber is done with a big frame before it receives again."""

    def claims(self, header: Dict[str, str], listener: str) -> bool:
        """Whether an inbound connection opening with ``header`` on the node's listening
        socket of protocol ``listener`` (``"TCPROS"``: its TCP port) is this protocol's: the
        node's server gives it to the first handler that claims it (TCPROS, last in the
        node's list, claims every topic connection on the TCP port)."""
        return False

    def accept(self, stream: Any, header: Dict[str, str], publication: PublicationSide) -> None:
        """Take an inbound connection this handler claimed, for ``publication``: negotiate
        and add the publisher's end to it; raises ``Rejected`` after refusing."""
        raise TransportException(f"{self.protocol} takes no inbound connections")

    def close(self) -> None:  # noqa: B027 - most handlers run nothing of their own
        """The node is shutting down: stop what this handler runs of its own (a server)."""


def subscriber_header(topic: str, data_class: Any, caller_id: str,
                      tcp_nodelay: bool = False) -> Dict[str, str]:
    """A subscriber's connection header for ``topic`` of ``data_class``, whatever the protocol
    (every subscriber of the node and ``minros web``'s taps send this one)."""
    return {
        "topic": topic,
        "message_definition": data_class._full_text,
        "tcp_nodelay": "1" if tcp_nodelay else "0",
        "md5sum": data_class._md5sum,
        "type": data_class._type,
        "callerid": caller_id,
    }
