"""rospy.topics' internals: the base of topic implementations (its connection bookkeeping)
and the poller that notices broken connections."""

from __future__ import annotations

import logging
import select
import threading
from typing import Any, Iterator, List

from minros import node as _node
from minros.wire.tcpros import DEFAULT_BUFF_SIZE  # noqa: F401

from .registration import TopicManager as _TopicManager  # noqa: F401

_logger = logging.getLogger("rospy.topics")


class Poller:
    """Descriptors watched for hang-up and error (epoll where there is one, else poll)."""

    def __init__(self) -> None:
        if hasattr(select, "epoll"):
            self.poller: Any = select.epoll()
            self._mask = select.EPOLLHUP | select.EPOLLERR | select.EPOLLRDHUP
            self._bad = select.EPOLLHUP | select.EPOLLERR | select.EPOLLRDHUP
        else:
            self.poller = select.poll()
            self._mask = select.POLLHUP | select.POLLERR
            self._bad = select.POLLHUP | select.POLLERR

    def add_fd(self, fd: int) -> None:
        self.poller.register(fd, self._mask)

    def remove_fd(self, fd: int) -> None:
        self.poller.unregister(fd)

    def error_iter(self) -> Iterator[int]:
        """The descriptors in error now (no waiting)."""
        for fd, event in self.poller.poll(0):
            if event & self._bad:
                yield fd


class _TopicImpl:
    """Connections of one topic, by endpoint (rospy's base of publisher and subscriber
    implementations): one connection per endpoint, a closed one removed by its callback."""

    def __init__(self, name: str, data_class: Any) -> None:
        self.resolved_name = _node.resolve_name(name)
        self.name = self.resolved_name
        self.data_class = data_class
        self.type = data_class._type
        self.handler = None
        self.seq = 0
        self.c_lock = threading.RLock()
        self.connections: List[Any] = []
        self.closed = False
        self.ref_count = 0
        self.connection_poll = Poller()

    def close(self) -> None:
        if self.closed:
            return
        self.closed = True
        with self.c_lock:
            for c in self.connections:
                try:
                    c.close()
                except Exception:
                    _logger.exception("closing a connection of [%s]", self.resolved_name)
            del self.connections[:]
        self.handler = None

    def get_num_connections(self) -> int:
        with self.c_lock:
            return len(self.connections)

    def has_connection(self, endpoint_id: str) -> bool:
        return any(c.endpoint_id == endpoint_id for c in self.connections)

    def has_connections(self) -> bool:
        return bool(self.connections)

    def _remove_connection(self, connections: List[Any], c: Any) -> None:
        fd = c.fileno()
        if fd is not None:
            try:
                self.connection_poll.remove_fd(fd)
            except (OSError, ValueError, KeyError):
                pass
        try:
            c.close()
        except Exception:
            pass
        if c in connections:
            connections.remove(c)

    def add_connection(self, c: Any) -> bool:
        """Add ``c``; an earlier connection to the same endpoint is closed and dropped."""
        with self.c_lock:
            if self.closed:
                return False
            fresh = list(self.connections)
            for old in self.connections:
                if old.endpoint_id == c.endpoint_id:
                    self._remove_connection(fresh, old)
            for fd in list(self.connection_poll.error_iter()):
                for broken in [x for x in fresh if x.fileno() == fd]:
                    self._remove_connection(fresh, broken)
            fd = c.fileno()
            if fd is not None:
                self.connection_poll.add_fd(fd)
            fresh.append(c)
            self.connections = fresh
            previous = c.cleanup_cb
            if previous is None:
                c.set_cleanup_callback(self.remove_connection)
            else:
                def both(transport: Any) -> None:
                    self.remove_connection(transport)
                    previous(transport)
                c.set_cleanup_callback(both)
            return True

    def check(self) -> None:
        broken = set(self.connection_poll.error_iter())
        if broken:
            with self.c_lock:
                fresh = list(self.connections)
                for c in [x for x in fresh if x.fileno() in broken]:
                    self._remove_connection(fresh, c)
                self.connections = fresh

    def remove_connection(self, c: Any) -> None:
        with self.c_lock:
            fresh = list(self.connections)
            self._remove_connection(fresh, c)
            self.connections = fresh
