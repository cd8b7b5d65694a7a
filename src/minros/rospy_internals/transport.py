"""rospy.impl.transport: the base of rospy's connections and protocol handlers."""

from __future__ import annotations

from typing import Any, Callable, List, Optional, Tuple

from minros.client.topics import _next_conn_id

#: directions of a transport, seen from this node
INBOUND = "i"
OUTBOUND = "o"
BIDIRECTIONAL = "b"


class Transport:
    """One connection: its direction, the peer it talks to, what went through it."""

    transport_type = "UNKNOWN"

    def __init__(self, direction: str, name: str = "unnamed") -> None:
        self.name = name
        self.direction = direction
        self.done = False
        self.cleanup_cb: Optional[Callable[[Any], Any]] = None
        self.endpoint_id = ""
        self.id = _next_conn_id()
        self.stat_bytes = 0
        self.stat_num_msg = 0
        self.local_endpoint: Tuple[Any, Any] = (0, 0)
        self.remote_endpoint: Tuple[Any, Any] = (0, 0)

    def fileno(self) -> Optional[int]:
        """A descriptor to poll, when there is one."""
        return None

    def set_cleanup_callback(self, cleanup_callback: Callable[[Any], Any]) -> None:
        self.cleanup_cb = cleanup_callback

    def close(self) -> None:
        self.done = True
        if self.cleanup_cb:
            self.cleanup_cb(self)

    def write_data(self, data: bytes) -> None:
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
    """A transport protocol a node offers (TCPROS): the interface rospy's handlers implement."""

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
