"""rospy.impl.transport: the base of rospy's connections and protocol handlers.

rospy's :class:`Transport` *is* a transport of minros's seam (:class:`minros.transport.base.Transport`)
under rospy's names, so a rospy connection (a TCPROSTransport made by rospy's TCPROSHandler, or
one of rospy code's own) joins a publication as a TCPROSSender does: ``send(frame)`` is rospy's
``write_data(bytes)``, ``info()`` its ``get_transport_info()``, ``stat_msgs`` its
``stat_num_msg``, and ``endpoint_id``/``transport_type`` are the names both use. rospy's
:class:`ProtocolHandler` keeps rospy's interface (``init_publisher`` is the seam's ``answer``,
``create_transport`` its ``connect``).
"""

from __future__ import annotations

from typing import Any, Callable, Dict, List, Optional, Tuple

from minros.exceptions import TransportException
from minros.transport import base
from minros.wire.handshake import Handshake

#: directions of a transport, seen from this node
INBOUND = "i"
OUTBOUND = "o"
BIDIRECTIONAL = "b"


class Transport(base.Transport):
    """One connection: its direction, the peer it talks to, what went through it."""

    transport_type = "UNKNOWN"
    # rospy keeps these as plain attributes; they shadow the seam's properties
    endpoint_id = ""
    stat_bytes = 0

    def __init__(self, direction: str, name: str = "unnamed") -> None:
        self.name = name
        self.direction = direction
        self.done = False
        self.cleanup_cb: Optional[Callable[[Any], Any]] = None
        self.endpoint_id = ""
        self.id = base.next_connection_id()
        self.stat_bytes = 0
        self.stat_num_msg = 0
        self.header: Dict[str, str] = {}
        self.local_endpoint: Tuple[Any, Any] = (0, 0)
        self.remote_endpoint: Tuple[Any, Any] = (0, 0)

    # -- the seam under rospy's names -----------------------------------------------------------

    @property
    def stat_msgs(self) -> int:
        return self.stat_num_msg

    @stat_msgs.setter
    def stat_msgs(self, value: int) -> None:
        self.stat_num_msg = value

    def send(self, frame: base.Frame) -> None:
        """A publication's frame, written as rospy writes: ``write_data`` of its bytes."""
        self.write_data(frame if frame.__class__ is bytes else b"".join(bytes(p) for p in frame))

    def negotiate(self, handshake: Handshake, opening: Dict[str, str] | None = None) -> None:
        raise TransportException(f"a {self.transport_type} transport of rospy's exchanges its "
                                 "headers itself (connect, write_header, read_header)")

    def info(self) -> str:
        try:
            return self.get_transport_info()
        except NotImplementedError:
            return f"{self.transport_type} connection to [{self.endpoint_id}]"

    # -- rospy's interface ----------------------------------------------------------------------

    def fileno(self) -> Optional[int]:
        """A descriptor to poll, when there is one."""
        return None

    def set_cleanup_callback(self, cleanup_callback: Callable[[Any], Any]) -> None:
        self.cleanup_cb = cleanup_callback

    def close(self) -> None:
        self.done = True
        if self.cleanup_cb:
            self.cleanup_cb(self)

    def write_data(self, data: bytes) -> Any:
        raise NotImplementedError("write_data is implemented by each transport")

    def send_message(self, msg: Any, seq: int) -> None:
        raise NotImplementedError("send_message is implemented by each transport")

    def receive_once(self) -> List[Any]:
        raise NotImplementedError("receive_once is implemented by each transport")

    def receive_loop(self, msgs_callback: Callable[..., Any]) -> None:
        raise NotImplementedError("receive_loop is implemented by each transport")

    def get_transport_info(self) -> str:
        raise NotImplementedError("get_transport_info is implemented by each transport")


class DeadTransport(Transport):
    """What remains of a closed transport (its statistics, for bus info)."""

    def __init__(self, transport: Transport) -> None:
        super().__init__(transport.direction, transport.name)
        self.transport_type = transport.transport_type
        self.id = transport.id
        self.stat_bytes = transport.stat_bytes
        self.stat_num_msg = transport.stat_num_msg
        self.done = True
        self.endpoint_id = transport.endpoint_id
        self.local_endpoint = transport.local_endpoint
        self.remote_endpoint = transport.remote_endpoint

    def get_transport_info(self) -> str:
        return (f"Closed {self.transport_type} connection on port {self.local_endpoint[1]} to "
                f"[{self.remote_endpoint[0]}:{self.remote_endpoint[1]}]")


class ProtocolHandler:
    """A transport protocol a node offers (TCPROS): the interface rospy's handlers implement
    (minros's is :class:`minros.transport.base.ProtocolHandler`: ``init_publisher`` is its
    ``answer``, ``create_transport`` its ``connect``, ``get_supported`` its ``offer``)."""

    def shutdown(self) -> None:
        """Close what the handler opened."""

    def create_transport(self, topic: str, pub_uri: str, protocol_params: List[Any]) -> Any:
        raise NotImplementedError("create_transport is implemented by each protocol handler")

    create_connection = create_transport

    def supports(self, protocol: str) -> bool:
        return False

    def get_supported(self) -> List[List[Any]]:
        return []

    def init_publisher(self, topic: str, protocol: List[Any]) -> Tuple[int, str, Any]:
        raise NotImplementedError("init_publisher is implemented by each protocol handler")
