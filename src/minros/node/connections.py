"""The node's connections: the transports it speaks and the one inbound server that takes
every connection to this node (started on first use, as rospy's TCPROS server), on its TCP port
and, for shared memory, its abstract Unix socket, handing each to what its header names.

One object owns the server and the protocol list, so the Node only asks: its address, the
answer to a requestTopic offer, a same-process link. It reads what it needs from the other
concerns through the callables it is given (names, registries, lifecycle), never the Node.
"""

from __future__ import annotations

import threading
from typing import Any, Callable, Dict, List, Tuple

from minros.exceptions import ROSInitException
from minros.node.names import NodeNames
from minros.node.registries import Registries
from minros.node.tcpros_server import TCP, TCPROS_LIMITS, TCPROSServer
from minros.transport import intraprocess, shm
from minros.transport.base import ProtocolHandler, Transport
from minros.transport.tcpros_pubsub import TCPROSHandler
from minros.wire import admission, tcpros
from minros.wire.handshake import route

__all__ = ["Connections"]


class Connections:
    """The protocols a node speaks (TCPROS last) and its TCPROS server."""

    def __init__(self, names: NodeNames, registries: Registries,
                 shutdown_requested: Callable[[], bool], started: Callable[[], bool]) -> None:
        self._names = names
        self._registries = registries
        self._shutdown_requested = shutdown_requested
        self._started = started  # the node's servers are up (init_node ran)
        #: the transports, in the order a subscriber offers them: shared memory (same host,
        #: minros peers) when this system has it, TCPROS last
        self.protocols: List[ProtocolHandler] = [TCPROSHandler(lambda: self.tcpros_address())]
        if shm.supported():
            self.protocols.insert(0, shm.ShmHandler(self.shm_address))
        self.host = ""  # the advertised host, set by start()
        self.port = 0  # the TCPROS port asked for (0: any free port)
        self.allowed: Any = None  # ROS_ALLOWED_HOSTS, set by start()
        #: the server's admission policy (read when the server starts)
        self.limits = TCPROS_LIMITS
        self.server: TCPROSServer | None = None
        self._lock = threading.Lock()

    def tcpros_address(self) -> Tuple[str, int]:
        """(advertised host, port) of the TCPROS server (started on first use)."""
        if not self._started():
            raise ROSInitException("client code must call rospy.init_node() first")
        with self._lock:
            if self.server is None:
                server = TCPROSServer(self.dispatch, self._shutdown_requested, self.allowed,
                                      what=f"node [{self._names.caller_id}]", limits=self.limits)
                server.start(self._names.bind_address(), self.port)
                self.server = server
            return self.host, self.server.port

    def shm_address(self) -> str:
        """The name of the server's abstract Unix socket (listening from the first call)."""
        self.tcpros_address()
        assert self.server is not None
        return self.server.unix_name()

    def answer_protocol(self, topic: str, offer: Any) -> List[Any] | None:
        """requestTopic: the answer to one offered protocol, None if we do not speak it."""
        if not isinstance(offer, list) or not offer:
            return None
        for handler in self.protocols:
            if handler.protocol == offer[0]:
                return handler.answer(topic, offer)
        return None

    def local_transport(self, topic: str, data_class: Any, fields: Dict[str, str]) -> Transport | None:
        """The subscriber's end of an intra-process link when this node's publication of
        ``topic`` hands its messages over as objects (``intraprocess``) of ``data_class``, the
        subscriber's (``fields``: its connection header); else None."""
        pub = self._registries.publications.get(topic)
        if pub is None or not pub.intraprocess or pub.closed or pub.data_class is not data_class:
            return None
        return intraprocess.link(pub, fields)

    def dispatch(self, stream: Any, header: Dict[str, str], conn: admission.Connection,
                 listener: str = TCP) -> str | None:
        """Hand an inbound connection (that arrived on the server's socket of protocol
        ``listener``) to what its header names; the error text when it cannot be."""
        kind = route(header)
        caller_id = self._names.caller_id
        if kind == "topic":
            if self._shutdown_requested():
                return "Node is shutting down"
            pub = self._registries.publications.get(header["topic"])
            if pub is None:
                return tcpros.publisher_header_error(
                    header, caller_id, self._registries.publication_types()) or (
                    f"[{caller_id}] is not a publisher of [{header['topic']}]")
            for handler in self.protocols:
                if handler.claims(header, listener):
                    handler.accept(stream, header, pub)  # Rejected when it refused
                    return None
            return "no transport takes this connection"
        if kind == "service":
            if listener != TCP:
                return "a shared-memory connection carries a topic"
            serve = self._registries.services.get(header["service"])
            if serve is None:
                return f"[{caller_id}] is not a provider of [{header['service']}]"
            serve(stream, header, conn)
            return None
        return "no topic or service name detected"

    def close(self) -> None:
        """Stop the server and every protocol's shared state."""
        if self.server is not None:
            self.server.close()
        for handler in self.protocols:
            handler.close()
