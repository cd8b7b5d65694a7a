"""A publication: every Publisher handle of one topic in this process, and its subscribers'
connections (rospy's _PublisherImpl).

Publishing serializes a message once (Header stamped first) and hands the same frame to every
connection's ``send``; the connections are transports of any protocol (``minros.transport``),
added by the protocol handler that accepted the subscriber. A publication made with
``intraprocess=True`` hands subscribers of this process the message object itself, through
the connections that take objects (``takes_objects``: the intra-process links); the others
get the frame, serialized only when one of them is there. ``loan(nbytes)`` lends the memory of
a message's large array from a connection that can send it in place (``lend``: a shared-memory
slot), so that publishing it copies nothing (the other connections get the frame as usual).
What each connection can do is declared by the transport seam (``minros.transport.base``), so
``publish`` is one loop over the connections, whatever their protocols. The publication keeps what ROS
keeps per topic: the latched message (sent first to every new subscriber), the sequence number,
the SubscribeListeners, the user's extra header fields.

Code written against rospy's ``_PublisherImpl`` finds its names here too (``add_connection``,
``publish(msg, connection_override)``, ``acquire``/``release``, ``has_connection``): rospy's
own transports (:mod:`minros.rospy_internals.transport`) are transports of this seam.
"""

from __future__ import annotations

import ctypes
import io
import logging
import struct
import threading
import traceback
from typing import TYPE_CHECKING, Any, Dict, List, Tuple

from minros.client.msg import args_kwds_to_message, frame_len, serialize_frame, stamp_header
from minros.exceptions import ROSException
from minros.transport.base import Transport

if TYPE_CHECKING:
    from minros.node import Node

__all__ = ["Publication"]

_logger = logging.getLogger("minros.client.topics")


class Publication:
    """Shared state of all Publisher handles for one topic in this process."""

    def __init__(self, node: Node, name: str, resolved_name: str, data_class: Any) -> None:
        self.node = node
        self.name = name
        self.resolved_name = resolved_name
        self.data_class = data_class
        self.type: str = data_class._type
        self.md5sum: str = data_class._md5sum
        self.connections: List[Transport] = []
        #: subscribers of this process get the published objects themselves (shared)
        self.intraprocess = False
        #: the loan not published yet: (the connection that lent it, its loan)
        self._loan: Tuple[Transport, Any] | None = None
        self.lock = threading.RLock()
        self.listeners: List[Any] = []
        self.headers: Dict[str, str] = {}
        self.is_latch = False
        self.latch: Any = None
        self.queue_size: int | None = None
        self.tcp_nodelay = False
        self.seq = 0
        self.message_data_sent = 0
        self.ref_count = 0
        self.closed = False

    # -- connections -------------------------------------------------------------------------

    def header_fields(self) -> Dict[str, str]:
        """What the publisher says in its connection header (the user's headers last)."""
        fields = {
            "topic": self.resolved_name,
            "type": self.type,
            "latching": "1" if self.is_latch else "0",
            "message_definition": self.data_class._full_text,
            "md5sum": self.md5sum,
            "callerid": self.node.caller_id,
        }
        fields.update(self.headers)
        return fields

    def add_connection(self, transport: Transport) -> bool:
        """A subscriber's negotiated connection: the latched message goes first, then the
        listeners hear of it. False (and the transport closed) when the publication is."""
        with self.lock:
            if self.closed:
                transport.close()
                return False
            self.connections = self.connections + [transport]
            if self.is_latch and self.latch is not None:
                self._send_one(transport, self.latch)
        for listener in list(self.listeners):
            def publish_single(*args: Any, _conn: Transport = transport, **kwds: Any) -> None:
                msg = args_kwds_to_message(self.data_class, args, kwds)
                with self.lock:
                    self._send_one(_conn, msg)
            try:
                listener.peer_subscribe(self.resolved_name, self._publish_any, publish_single)
            except Exception:
                _logger.error("peer_subscribe failed: %s", traceback.format_exc())
        return True

    def remove_connection(self, transport: Transport) -> None:
        """A connection ended (the subscriber left or failed)."""
        with self.lock:
            if transport not in self.connections:
                return
            self.connections = [c for c in self.connections if c is not transport]
            remaining = len(self.connections)
        for listener in list(self.listeners):
            try:
                listener.peer_unsubscribe(self.resolved_name, remaining)
            except Exception:
                _logger.error("peer_unsubscribe failed: %s", traceback.format_exc())

    def _publish_any(self, *args: Any, **kwds: Any) -> None:
        self.publish(args_kwds_to_message(self.data_class, args, kwds))

    # -- publishing --------------------------------------------------------------------------

    def _send_one(self, conn: Transport, msg: Any) -> None:
        """Called with the lock held: ``msg`` to one connection."""
        self.seq += 1
        stamp_header(msg, self.seq)
        if conn.takes_objects:
            conn.put(msg)
            return
        frame = serialize_frame(msg)
        self.message_data_sent += frame_len(frame) - 4
        conn.send(frame)

    def publish(self, msg: Any, connection_override: Transport | None = None) -> None:
        """Send ``msg`` to every connection, or to ``connection_override`` only (rospy's way
        of sending to one subscriber); a latching publication keeps it for newcomers."""
        with self.lock:
            if self.closed:
                if self.node.is_shutdown():
                    return
                raise ROSException("publish() to a closed topic")
            if self.is_latch:
                self.latch = msg
            conns = self.connections if connection_override is None else [connection_override]
            loan = self._loan
            if not conns:
                self._give_back()
                return
            # Header auto-fill, then one serialization for every connection that takes frames
            self.seq += 1
            try:
                has_header = msg._has_header
            except AttributeError:  # not a message class of ours (rospy code's own)
                has_header = False
            if has_header:
                stamp_header(msg, self.seq)
            frame = None
            for conn in conns:
                if conn.takes_objects:  # an intra-process link: the object itself
                    conn.put(msg)
                    continue
                if loan is not None and conn is loan[0]:
                    self._loan = None
                    size = self._send_loaned(conn, loan[1], msg)
                    loan = None
                    if size:  # the array's own slot: nothing copied
                        self.message_data_sent += size
                        continue
                if frame is None:
                    frame = serialize_frame(msg)
                    self.message_data_sent += (len(frame) if frame.__class__ is bytes
                                               else frame_len(frame)) - 4
                conn.send(frame)

    # -- loans -------------------------------------------------------------------------------

    def loan(self, nbytes: int) -> memoryview:
        """Writable memory for a message's large ``uint8[]`` array (``nbytes``), to fill in
        place and publish in the next message: from a shared-memory connection's slot when
        there is one (no copy at all then), else plain memory (a latched or intra-process
        publication, no such subscriber). One loan at a time: a new one cancels the last."""
        if not isinstance(nbytes, int) or nbytes < 0:
            raise ValueError("loan(nbytes): nbytes must be a non-negative int")
        with self.lock:
            self._give_back()
            if not self.is_latch and not self.intraprocess and nbytes:
                for conn in self.connections:
                    loaned = conn.lend(nbytes)
                    if loaned is not None:
                        self._loan = (conn, loaned)
                        return loaned.view
        return memoryview(bytearray(nbytes))

    def _give_back(self) -> None:
        """Called with the lock held: cancel the loan not published."""
        loan, self._loan = self._loan, None
        if loan is not None:
            loan[0].give_back(loan[1])

    @staticmethod
    def _send_loaned(conn: Transport, loaned: Any, msg: Any) -> int:
        """Called with the lock held: send ``msg`` in place to ``conn``, which lent its array
        (``loaned``); the bytes sent, or 0 when it could not be (the loan went back: the
        message is sent as any other)."""
        view = loaned.view
        parts: List[Any] = []
        try:
            msg._serialize_parts(parts.append)
        except Exception:  # noqa: BLE001 - serialize_frame says what is wrong, after this
            conn.give_back(loaned)
            return 0
        address = _address(view)
        for i, part in enumerate(parts):
            if part.__class__ is memoryview and part.nbytes == view.nbytes and \
                    _address(part) == address:
                head = b"".join(parts[:i])
                tail = b"".join(parts[i + 1:])
                size = len(head) + view.nbytes + len(tail)
                return size if conn.send_loaned(loaned, _U32.pack(size) + head, tail) else 0
        conn.give_back(loaned)  # the message does not hold it
        return 0

    # -- bookkeeping -------------------------------------------------------------------------

    def get_stats(self) -> list:
        return [self.resolved_name, self.message_data_sent,
                [[c.id, c.stat_bytes, c.stat_msgs, not c.done] for c in self.connections]]

    def has_connection(self, endpoint_id: str) -> bool:
        """rospy's query: is the subscriber node ``endpoint_id`` (its caller id) connected?"""
        return any(c.endpoint_id == endpoint_id and not c.done for c in self.connections)

    def has_connections(self) -> bool:
        return any(not c.done for c in self.connections)

    def get_num_connections(self) -> int:
        return sum(1 for c in self.connections if not c.done)

    def get_stats_info(self) -> list:
        return [[c.id, c.endpoint_id, "o", c.transport_type, self.resolved_name, True,
                 c.info()] for c in self.connections]

    # rospy's _PublisherImpl names, for code written against them

    @property
    def buff(self) -> io.BytesIO:
        """rospy's serialization buffer, empty between publishes: one here serializes into a
        frame of its own each time, so this one is always empty."""
        return io.BytesIO()

    def acquire(self) -> None:
        self.lock.acquire()

    def release(self) -> None:
        self.lock.release()

    def close(self) -> None:
        with self.lock:
            self.closed = True
            self._give_back()
            conns, self.connections = self.connections, []
        for conn in conns:
            conn.close()


_U32 = struct.Struct("<I")


def _address(buf: Any) -> int:
    """Where a writable buffer's memory starts (-1 for a read-only one)."""
    try:
        return ctypes.addressof(ctypes.c_char.from_buffer(buf))
    except (TypeError, ValueError):
        return -1
