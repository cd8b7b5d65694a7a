"""INTRAPROCESS: a publisher and a subscriber of one node hand over the message object itself,
without serialization, sockets or a requestTopic (roscpp's intra-process links, which
getBusInfo also names INTRAPROCESS).

A publication does this only when asked (``Publisher(..., intraprocess=True)``): the
subscriber's callbacks then get the very object the publisher passed to ``publish()``, shared
by every subscriber of the process, as roscpp shares a published ``boost::shared_ptr``. Neither
side may change it afterwards. A subscriber whose class differs from the publisher's (an
AnyMsg, a numpy_msg variant) is connected as any other, serialized.

The link keeps the subscriber's threading: the publisher appends to a queue (bounded by the
publication's queue_size, oldest dropped; a synchronous publisher waits until the subscriber
took the previous message) and the subscriber's connection thread runs the callbacks.
"""

from __future__ import annotations

import collections
import threading
import time
from typing import Any, Callable, Deque, Dict, List

from minros.msgs import reader_for
from minros.transport.base import Frame, PublicationSide, Transport, next_connection_id
from minros.wire.handshake import Handshake

__all__ = ["INTRAPROCESS", "IntraProcessPublisher", "IntraProcessSubscriber", "link"]

INTRAPROCESS = "INTRAPROCESS"
#: a synchronous publisher waits at most this long for its subscriber to take a message
SYNC_TIMEOUT = 60.0


class _Queue:
    """What both ends share: the messages handed over and not taken yet."""

    def __init__(self, limit: int | None) -> None:
        self.items: Deque[Any] = collections.deque()
        self.limit = limit  # None: synchronous; 0: unbounded
        self.cond = threading.Condition()
        self.closed = False
        self.taker: threading.Thread | None = None


class IntraProcessPublisher(Transport):
    """The publication's end: ``put(msg)`` hands a message over."""

    protocol = INTRAPROCESS
    #: the publication hands this end objects (``put``), not frames
    takes_objects = True

    def __init__(self, queue: _Queue, header: Dict[str, str],
                 on_close: Callable[[Transport], Any], data_class: Any = None) -> None:
        self.id = next_connection_id()
        self.read: Callable[[Any], Any] = reader_for(data_class) if data_class is not None \
            else _same
        self.queue = queue
        self.header = header  # the subscriber's side of it
        self.stat_msgs = 0
        self.done = False
        self.on_close = on_close

    @property
    def stat_bytes(self) -> int:
        return 0

    @property
    def endpoint_id(self) -> str:
        return self.header.get("callerid", "")

    def negotiate(self, handshake: Handshake, opening: Dict[str, str] | None = None) -> None:
        pass

    def info(self) -> str:
        return f"INTRAPROCESS connection to [{self.endpoint_id}]"

    def send(self, frame: Frame) -> None:
        """A frame (rospy code writing bytes to each connection): read into a new message, as
        a subscriber over a socket would get it, and handed over."""
        body = frame if frame.__class__ is bytes else b"".join(frame)  # type: ignore[arg-type]
        self.put(self.read(memoryview(body)[4:]))

    def put(self, msg: Any) -> None:
        """Hand ``msg`` over; drops the oldest waiting one when the queue is full."""
        queue = self.queue
        with queue.cond:
            if queue.closed:
                return
            items = queue.items
            if queue.limit is None and threading.current_thread() is not queue.taker:
                deadline = time.monotonic() + SYNC_TIMEOUT
                while items and not queue.closed:
                    remaining = deadline - time.monotonic()
                    if remaining <= 0:
                        items.clear()  # a stuck subscriber: it loses what waited
                        break
                    queue.cond.wait(remaining)
                if queue.closed:
                    return
            elif queue.limit and len(items) >= queue.limit:
                items.popleft()
            items.append(msg)
            self.stat_msgs += 1
            queue.cond.notify_all()
        # Let the subscriber's thread have the GIL now rather than after the interpreter's
        # switch interval (5 ms), or a publishing loop starves it (as TCPROSSender does).
        time.sleep(0)

    def close(self) -> None:
        queue = self.queue
        with queue.cond:
            if self.done:
                return
            self.done = True
            queue.closed = True
            queue.cond.notify_all()


class IntraProcessSubscriber(Transport):
    """The subscription's end: ``receive`` returns the objects handed over."""

    protocol = INTRAPROCESS

    def __init__(self, queue: _Queue, header: Dict[str, str], publisher: IntraProcessPublisher,
                 ) -> None:
        self.id = next_connection_id()
        self.queue = queue
        self.header = header  # the publisher's connection header, as over TCPROS
        self.stat_msgs = 0
        self.done = False
        self.publisher = publisher

    @property
    def stat_bytes(self) -> int:
        return 0

    def negotiate(self, handshake: Handshake, opening: Dict[str, str] | None = None) -> None:
        pass

    def info(self) -> str:
        return f"INTRAPROCESS connection to [{self.header.get('callerid', '')}]"

    def message_reader(self, data_class: Any) -> Callable[[Any], Any]:
        return _same

    def receive(self) -> List[Any] | None:
        queue = self.queue
        with queue.cond:
            queue.taker = threading.current_thread()
            while not queue.items and not queue.closed:
                queue.cond.wait()
            if queue.closed:
                return None
            items = list(queue.items)
            queue.items.clear()
            queue.cond.notify_all()  # a synchronous publisher waits for room
            return items

    def close(self) -> None:
        queue = self.queue
        with queue.cond:
            if self.done:
                return
            self.done = True
            queue.closed = True
            queue.cond.notify_all()
        publisher = self.publisher
        if not publisher.done:
            publisher.done = True
            # the publication takes its own lock: never from a thread that may hold it (at
            # interpreter shutdown, when no thread may start, the publication is going too)
            try:
                threading.Thread(target=publisher.on_close, args=(publisher,), daemon=True,
                                 name="minros-intraprocess-close").start()
            except RuntimeError:
                pass


def _same(msg: Any) -> Any:
    return msg


def link(publication: PublicationSide, fields: Dict[str, str]) -> IntraProcessSubscriber:
    """Connect a subscriber of this process (``fields``: its connection header) to
    ``publication``; returns the subscriber's end, the publisher's end joined the
    publication (which sends it the latched message first)."""
    queue = _Queue(publication.queue_size)
    publisher = IntraProcessPublisher(queue, dict(fields), publication.remove_connection,
                                      publication.data_class)
    subscriber = IntraProcessSubscriber(queue, publication.header_fields(), publisher)
    publication.add_connection(publisher)
    return subscriber
