"""rospy.impl.tcpros_pubsub: the TCPROS protocol of topics (header fields of each side) and
rospy's TCPROS handler over the node's (:mod:`minros.transport.tcpros_pubsub`): what a publisher
answers is the node's answer (``Node.answer_protocol``), an inbound subscriber connection
checked here becomes a rospy TCPROSTransport among the publication's transports, and outbound
connections are made by the node's subscription."""

from __future__ import annotations

import socket
import threading
import time
from typing import Any, Dict, List, Optional, Tuple, cast

from minros import node as _node
from minros.names import TOPIC_ANYTYPE

from . import registration
from .tcpros_base import (  # noqa: F401 - rospy.impl.tcpros_pubsub's namespace has them
    DEFAULT_BUFF_SIZE,
    TCPROS,
    TCPROSTransport,
    TCPROSTransportProtocol,
    get_tcpros_server_address,
)
from .transport import INBOUND, OUTBOUND, ProtocolHandler


class TCPROSSub(TCPROSTransportProtocol):
    """The subscriber's side of a topic connection."""

    def __init__(self, resolved_name: str, recv_data_class: Any, queue_size: Optional[int] = None,
                 buff_size: int = DEFAULT_BUFF_SIZE, tcp_nodelay: bool = False) -> None:
        super().__init__(resolved_name, recv_data_class, queue_size, buff_size)
        self.direction = INBOUND
        self.tcp_nodelay = tcp_nodelay

    def get_header_fields(self) -> Dict[str, str]:
        cls = self.recv_data_class
        return {"topic": self.resolved_name, "message_definition": cls._full_text,
                "tcp_nodelay": "1" if self.tcp_nodelay else "0", "md5sum": cls._md5sum,
                "type": cls._type, "callerid": _node.get_caller_id()}


class TCPROSPub(TCPROSTransportProtocol):
    """The publisher's side of a topic connection (``headers``: extra fields it sends)."""

    def __init__(self, resolved_name: str, pub_data_class: Any, is_latch: bool = False,
                 headers: Optional[Dict[str, str]] = None) -> None:
        super().__init__(resolved_name, None, queue_size=None, buff_size=128)
        self.pub_data_class = pub_data_class
        self.direction = OUTBOUND
        self.is_latch = is_latch
        self.headers = headers if headers else {}

    def get_header_fields(self) -> Dict[str, str]:
        cls = self.pub_data_class
        fields = {"topic": self.resolved_name, "type": cls._type,
                  "latching": "1" if self.is_latch else "0",
                  "message_definition": cls._full_text, "md5sum": cls._md5sum,
                  "callerid": _node.get_caller_id()}
        fields.update(self.headers)
        return fields


def _configure_pub_socket(sock: socket.socket, is_tcp_nodelay: bool) -> None:
    """TCP_NODELAY on a publisher's socket when asked."""
    if is_tcp_nodelay:
        sock.setsockopt(socket.IPPROTO_TCP, socket.TCP_NODELAY, 1)


class TCPROSHandler(ProtocolHandler):
    """TCPROS for this node's topics."""

    def __init__(self) -> None:
        self.tcp_nodelay_map: Dict[str, bool] = {}

    def set_tcp_nodelay(self, resolved_name: str, tcp_nodelay: bool) -> None:
        self.tcp_nodelay_map[resolved_name] = tcp_nodelay

    def shutdown(self) -> None:
        """The node's TCPROS server stops with the node."""

    def create_transport(self, resolved_name: str, pub_uri: str,
                         protocol_params: List[Any]) -> Tuple[int, str, Any]:
        """Connect our subscription of ``resolved_name`` to the publisher at ``pub_uri``."""
        if type(protocol_params) is not list or len(protocol_params) != 3:
            return 0, "ERROR: invalid TCPROS parameters", 0
        if protocol_params[0] != TCPROS:
            return 0, f"INTERNAL ERROR: protocol id is not TCPROS: {protocol_params[0]}", 0
        sub = registration.get_topic_manager().get_subscriber_impl(resolved_name)
        if sub is None:
            return 0, f"ERROR: not subscribed to [{resolved_name}]", 0
        sub.publisher_update(list(dict.fromkeys(sub.publisher_uris + [pub_uri])))
        return 1, f"Connected topic[{resolved_name}]. Transport impl[TCPROSTransport]", protocol_params[2]

    def supports(self, protocol: str) -> bool:
        return protocol == TCPROS

    def get_supported(self) -> List[List[Any]]:
        return [[TCPROS]]

    def init_publisher(self, resolved_name: str, protocol: List[Any]) -> Tuple[int, str, Any]:
        """The TCPROS parameters subscribers connect with: ``[TCPROS, host, port]``."""
        if protocol[0] != TCPROS:
            return 0, f"Internal error: protocol does not match TCPROS: {protocol}", []
        answer = _node.default_node().answer_protocol(resolved_name, protocol)
        if answer is None:
            return 0, f"Internal error: the node does not speak {TCPROS}", []
        return 1, f"ready on {answer[1]}:{answer[2]}", answer

    def topic_connection_handler(self, sock: socket.socket, client_addr: Any,
                                 header: Dict[str, str]) -> Optional[str]:
        """Check a subscriber's header and give its connection to our publication; the error
        text to send back when it cannot be."""
        if _node.is_shutdown_requested():
            return "Node is shutting down"
        for required in ("topic", "md5sum", "callerid"):
            if required not in header:
                return f"Missing required '{required}' field"
        name, md5sum = header["topic"], header["md5sum"]
        tm = registration.get_topic_manager()
        topic = tm.get_publisher_impl(name)
        if not topic:
            return (f"[{_node.get_caller_id()}] is not a publisher of [{name}]. Topics are "
                    f"{tm.get_publications()}")
        if not topic.data_class or topic.closed:
            return f"Internal error processing topic [{name}]"
        actual_md5, actual_type = topic.data_class._md5sum, topic.data_class._type
        if md5sum != TOPIC_ANYTYPE and md5sum != actual_md5:
            requested_type = header.get("type", actual_type)
            if requested_type != actual_type:
                return f"topic types do not match: [{requested_type}] vs. [{actual_type}]"
            return (f"Client [{header['callerid']}] wants topic [{name}] to have datatype/md5sum "
                    f"[{requested_type}/{md5sum}], but our version has [{actual_type}/{actual_md5}]"
                    " Dropping connection.")
        if "tcp_nodelay" in header:
            nodelay = header["tcp_nodelay"].strip() == "1"
        else:
            nodelay = self.tcp_nodelay_map.get(name, False)
        _configure_pub_socket(sock, nodelay)
        protocol = TCPROSPub(name, topic.data_class, is_latch=topic.is_latch, headers=topic.headers)
        transport = TCPROSTransport(protocol, name)
        transport.set_socket(sock, header["callerid"])
        transport.remote_endpoint = client_addr
        transport.write_header()
        # rospy's rule: a subscriber's new connection replaces its old one, and a transport
        # that closes leaves the publication
        for old in [c for c in topic.connections if c.endpoint_id == transport.endpoint_id]:
            topic.remove_connection(old)
            try:
                old.close()
            except Exception:  # a connection leaving must not stop the new one
                pass
        transport.set_cleanup_callback(topic.remove_connection)
        topic.add_connection(transport)
        return None


def check_if_still_publisher(resolved_topic_name: str, pub_uri: str) -> bool:
    """Whether the node at ``pub_uri`` still publishes ``resolved_topic_name`` (False when it
    does not answer)."""
    from .core import xmlrpcapi
    from .names import get_name

    try:
        proxy = xmlrpcapi(pub_uri, cache=False)
        if proxy is None:
            return False
        code, _msg, val = cast(Any, proxy.getPublications(get_name()))
        return code == 1 and any(topic == resolved_topic_name for topic, _type in val)
    except Exception:  # a dead or foreign peer: not a publisher any more
        return False


def robust_connect_subscriber(conn: Any, dest_addr: str, dest_port: int, pub_uri: str,
                              receive_cb: Any, resolved_topic_name: str) -> None:
    """Connect ``conn`` (a TCPROSTransport) to a publisher, retrying with a doubling interval
    while the peer still publishes the topic, then run its receive loop."""
    from minros.exceptions import TransportInitError

    from .core import is_shutdown, rospyerr

    interval = 0.5
    while conn.socket is None and not conn.done and not is_shutdown():
        try:
            conn.connect(dest_addr, dest_port, pub_uri, timeout=60.0)
        except TransportInitError as exc:
            if conn.protocol is None:
                conn.done = True
                break
            rospyerr("unable to create subscriber transport: %s.  Will try again in %ss", exc, interval)
            interval = min(interval * 2, 30.0)
            time.sleep(interval)
            conn.done = not check_if_still_publisher(resolved_topic_name, pub_uri)
    if not conn.done:
        conn.receive_loop(receive_cb)


class QueuedConnection:
    """A transport whose ``write_data`` queues (dropping the oldest beyond ``queue_size``;
    0 is unbounded) while a thread of its own writes to the wrapped transport; other
    attributes are the wrapped transport's. A write error is raised by the next write_data."""

    def __init__(self, connection: Any, queue_size: int) -> None:
        self._connection = connection
        self._queue_size = queue_size
        self._lock = threading.Lock()
        self._cond_data_available = threading.Condition(self._lock)
        self._queue: List[Any] = []
        self._error: Optional[BaseException] = None
        connection.set_cleanup_callback(self._closed_connection_callback)
        self._thread = threading.Thread(target=self._run, daemon=True,
                                        name=f"QueuedConnection {getattr(connection, 'name', '')}")
        self._thread.start()

    def _closed_connection_callback(self, connection: Any) -> None:
        with self._lock:
            self._cond_data_available.notify()

    def __getattr__(self, name: str) -> Any:
        if name.startswith("__"):
            raise AttributeError(name)
        return getattr(self._connection, name)

    def write_data(self, data: bytes) -> bool:
        with self._lock:
            if self._error is not None:
                error, self._error = self._error, None
                raise error
            if self._queue_size > 0 and len(self._queue) >= self._queue_size:
                del self._queue[0]
            self._queue.append(data)
            self._cond_data_available.notify()
        return True

    def _run(self) -> None:
        while not self._connection.done:
            with self._lock:
                while not self._queue and not self._connection.done:
                    self._cond_data_available.wait()
                batch, self._queue = self._queue, []
            for data in batch:
                try:
                    self._connection.write_data(data)
                except Exception as exc:  # handed to the writer's next call
                    with self._lock:
                        self._error = exc
