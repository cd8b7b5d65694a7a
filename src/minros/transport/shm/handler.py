"""MINROSSHM as a :class:`~minros.transport.base.ProtocolHandler`: offered first by a minros
subscriber, answered by a publisher of the same kernel with the name of its node's abstract
Unix socket (one per node, a listening socket of the node's one inbound server, under the
node's admission rules), and carried on that socket.
"""

from __future__ import annotations

import socket
from typing import Any, Callable, Dict, List

from minros.transport.base import FallBack, ProtocolHandler, PublicationSide, Transport
from minros.transport.shm.receiver import ShmReceiver
from minros.transport.shm.segment import boot_id, why
from minros.transport.shm.sender import ShmSender
from minros.transport.tcpros_base import CONNECT_TIMEOUT
from minros.wire import shm, trace
from minros.wire.handshake import Handshake, Role, route

__all__ = ["ShmHandler"]


class ShmHandler(ProtocolHandler):
    """MINROSSHM for a node whose abstract Unix socket is named ``address()`` (started on the
    first answer, OSError when it cannot be)."""

    protocol = shm.PROTOCOL

    def __init__(self, address: Callable[[], str]) -> None:
        self.boot_id = boot_id()
        self.address = address
        self.declined: Dict[str, str] = {}  # topic -> why shared memory failed for it

    def offer(self) -> List[Any]:
        return shm.offer(self.boot_id)

    def answer(self, topic: str, offer: List[Any]) -> List[Any] | None:
        if shm.check_offer(offer, self.boot_id) is not None or topic in self.declined:
            return None
        try:
            name = self.address()
        except OSError:  # no socket: the subscriber's next offer (TCPROS) is taken
            return None
        return shm.answer(name, self.boot_id)

    def connect(self, answer: List[Any], topic: str, buff_size: int, reuse_big: bool,
                tcp_nodelay: bool) -> Transport:
        name = shm.parse_answer(answer, self.boot_id)
        sock = socket.socket(socket.AF_UNIX, socket.SOCK_STREAM)
        sock.settimeout(CONNECT_TIMEOUT)
        try:
            sock.bind("")  # an abstract name of our own, so traces can tell connections apart
            sock.connect("\0" + name)
        except OSError as exc:
            sock.close()
            raise FallBack(f"cannot reach the publisher's shared-memory socket: {why(exc)} "
                           "(another network namespace?)") from None
        return ShmReceiver(trace.watch(sock, "connect", shm.PROTOCOL), topic)

    def claims(self, header: Dict[str, str], listener: str) -> bool:
        return listener == shm.PROTOCOL and route(header) == "topic"

    def accept(self, stream: Any, header: Dict[str, str], publication: PublicationSide) -> None:
        refuse = None
        if publication.closed:
            refuse = f"Internal error processing topic [{publication.resolved_name}]"
        handshake = Handshake(Role.PUBLISHER, publication.header_fields(), refuse=refuse)
        sender = ShmSender(stream, publication.resolved_name, publication.queue_size,
                           publication.remove_connection, self._fell_back)
        sender.negotiate(handshake, header)
        publication.add_connection(sender)

    def _fell_back(self, topic: str, reason: str) -> None:
        self.declined[topic] = reason
