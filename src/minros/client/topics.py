"""rospy's topic API: Publisher, Subscriber, SubscribeListener, wait_for_message.

A process has one publication and one subscription per topic however many handles share it
(rospy's topic manager): ``Publisher(...)`` and ``Subscriber(...)`` take a reference on it, made
and registered with the master on first use, and ``unregister()`` drops it. What happens on the
wire lives below: :mod:`minros.client.publication` and :mod:`minros.client.subscription` (one
topic, its connections), :mod:`minros.client.msg` (frames), :mod:`minros.transport` (how bytes
move: TCPROS, or any protocol handler the node has).
"""

from __future__ import annotations

import threading
import time
import warnings
from typing import Any, Callable, Dict, List, Tuple, Union

from minros import node as _node_mod
from minros.client.msg import AnyMsg, args_kwds_to_message, serialize_frame
from minros.client.publication import Publication
from minros.client.subscription import Subscription
from minros.exceptions import ROSException, ROSInterruptException
from minros.names import ANYTYPE
from minros.wire.masterapi import RemoteError
from minros.wire.tcpros import DEFAULT_BUFF_SIZE

__all__ = [
    "AnyMsg",
    "Publisher",
    "SubscribeListener",
    "Subscriber",
    "Topic",
    "args_kwds_to_message",
    "get_published_topics",
    "serialize_frame",
    "wait_for_message",
]

# ---------------------------------------------------------------------------------------------
# the topic manager: one publication and one subscription per topic, reference counted

#: guards the reference counts of the publication/subscription objects (a leaf: the master
#: is called outside it, so a slow master does not block other threads' Publisher() calls)
_impl_lock = threading.Lock()
#: makes a new subscription's topic statistics (or None); set by init_node (client/statistics)
#: so that the receive loop wraps its deliver only when statistics are on
statistics_factory: Callable[[Any], Any] | None = None

Endpoint = Union[Publication, Subscription]


def _check(name: str, data_class: Any) -> None:
    if not isinstance(name, str) or not name:
        raise ValueError("topic name must be a non-empty string")
    if data_class is None or not hasattr(data_class, "_md5sum"):
        raise ValueError(f"data_class [{data_class}] is not a message data class")


def _acquire(registry: Dict[str, Any], make: Callable[[], Any], add: Callable[[Any], None],
             resolved: str, data_class: Any, what: str) -> Tuple[Any, bool]:
    """(endpoint, fresh): the live endpoint of ``resolved`` in ``registry`` with one more
    reference, or a new one from ``make()``, put in the registry by ``add`` at once (so that a
    second handle made meanwhile finds it); the caller registers a fresh one with the master,
    outside the lock."""
    with _impl_lock:
        impl: Any = registry.get(resolved)
        fresh = impl is None or impl.closed
        if fresh:
            impl = make()
        elif impl.md5sum != data_class._md5sum and ANYTYPE not in (impl.md5sum, data_class._md5sum):
            raise ROSException(
                f"{what} for [{resolved}] already exists with a different type [{impl.type}]")
        impl.ref_count += 1
        if fresh:
            add(impl)
        return impl, fresh


def acquire_publication(name: str, data_class: Any, intraprocess: bool = False) -> Publication:
    """The process's publication of topic ``name``, with one more reference (``intraprocess``:
    set before anyone can connect to it)."""
    _check(name, data_class)
    me = _node_mod.default_node()
    resolved = me.resolve_topic_name(name)

    def make() -> Publication:
        made = Publication(me, name, resolved, data_class)
        made.intraprocess = intraprocess
        return made

    pub, fresh = _acquire(me.publications, make,
                          lambda p: me.add_publication(p, announce=False), resolved, data_class,
                          "publisher")
    if fresh:
        me.registration.announce_publication(pub)
    return pub


def acquire_subscription(name: str, data_class: Any,
                         configure: Callable[[Subscription], None] | None = None) -> Subscription:
    """The process's subscription to topic ``name``, with one more reference. ``configure``
    sets a fresh one up before it is announced (its first connection's header and queue are
    then the caller's: tcp_nodelay, buff_size, queue_size)."""
    _check(name, data_class)
    me = _node_mod.default_node()
    resolved = me.resolve_topic_name(name)
    sub, fresh = _acquire(me.subscriptions, lambda: Subscription(me, name, resolved, data_class),
                          lambda s: me.add_subscription(s, announce=False), resolved, data_class,
                          "subscriber")
    if fresh:
        if configure is not None:
            configure(sub)
        if statistics_factory is not None:
            sub.statistics = statistics_factory(sub)  # before any connection starts
        me.registration.announce_subscription(sub)
    return sub


def release(impl: Endpoint) -> None:
    """One reference fewer on ``impl``; the last one closes it and unregisters it."""
    with _impl_lock:
        impl.ref_count -= 1
        if impl.ref_count > 0:
            return
        impl.close()
    if isinstance(impl, Publication):
        impl.node.remove_publication(impl)
    else:
        impl.node.remove_subscription(impl)


class Topic:
    """Base of Publisher and Subscriber (rospy.topics.Topic)."""

    _kind = ""
    impl: Any

    def __init__(self, name: str, data_class: Any, intraprocess: bool = False,
                 configure: Callable[[Any], None] | None = None) -> None:
        if self._kind == "pub":
            self.impl = acquire_publication(name, data_class, intraprocess)
        else:
            self.impl = acquire_subscription(name, data_class, configure)
        self.name = self.impl.resolved_name
        self.resolved_name = self.impl.resolved_name
        self.data_class = data_class
        self.type = data_class._type
        self.md5sum = data_class._md5sum
        self.reg_type = self._kind

    def get_num_connections(self) -> int:
        impl = self.impl
        return 0 if impl is None else impl.get_num_connections()

    def unregister(self) -> None:
        impl, self.impl = self.impl, None
        if impl is not None:
            release(impl)


class SubscribeListener:
    """Notified when subscribers connect to or disconnect from a Publisher."""

    def peer_subscribe(self, topic_name: str, topic_publish: Callable, peer_publish: Callable) -> None:
        pass

    def peer_unsubscribe(self, topic_name: str, num_peers: int) -> None:
        pass


class Publisher(Topic):
    """Publish messages of ``data_class`` on topic ``name`` (rospy.Publisher)."""

    _kind = "pub"

    def __init__(self, name: str, data_class: Any, subscriber_listener: SubscribeListener | None = None,
                 tcp_nodelay: bool = False, latch: bool = False, headers: Dict[str, str] | None = None,
                 queue_size: int | None = None, intraprocess: bool = False) -> None:
        """rospy's arguments, and minros's ``intraprocess``: subscribers in this process get
        the published message objects themselves, without serialization, as roscpp's
        intra-process delivery of a published shared_ptr. The object is then shared: do not
        change a message after publishing it, nor one a callback receives."""
        super().__init__(name, data_class, intraprocess)
        impl = self.impl
        if subscriber_listener:
            impl.listeners.append(subscriber_listener)
        if tcp_nodelay:
            impl.tcp_nodelay = True
        if latch:
            impl.is_latch = True
        if headers:
            impl.headers.update({str(k): str(v) for k, v in headers.items()})
        if queue_size is not None:
            if not isinstance(queue_size, int) or queue_size < 0:
                raise ROSException("queue_size must be a non-negative integer or None")
            impl.queue_size = queue_size
        else:
            warnings.warn(
                "The publisher should be created with an explicit keyword argument 'queue_size'. "
                "Please see http://wiki.ros.org/rospy/Overview/Publishers%20and%20Subscribers "
                "for more information.", SyntaxWarning, stacklevel=2)

    def loan(self, nbytes: int) -> memoryview:
        """minros: writable memory for the large ``uint8[]`` array of the next message
        (``nbytes``: ``Image.data``, ``PointCloud2.data``), to fill in place and put in the
        message before ``publish()``. With a subscriber on shared memory it is that
        subscriber's slot, so the message is published without a copy; otherwise plain
        memory. Fill it before publishing and not after; one loan at a time."""
        impl = self.impl
        if impl is None:
            raise ROSException("loan() on an unregistered() handle")
        view: memoryview = impl.loan(nbytes)
        return view

    def publish(self, *args: Any, **kwds: Any) -> None:
        """Publish a message instance, or build one from positional or keyword fields."""
        impl = self.impl
        if impl is None:
            raise ROSException("publish() to an unregistered() handle")
        if not impl.node.initialized:
            raise ROSException("ROS node has not been initialized yet. Please call init_node() first")
        if len(args) == 1 and not kwds and args[0].__class__ is self.data_class:
            impl.publish(args[0])  # the common case, without the argument juggling
        else:
            impl.publish(args_kwds_to_message(self.data_class, args, kwds))


class Subscriber(Topic):
    """Receive messages of ``data_class`` on topic ``name`` (rospy.Subscriber)."""

    _kind = "sub"

    def __init__(self, name: str, data_class: Any, callback: Callable | None = None,
                 callback_args: Any = None, queue_size: int | None = None,
                 buff_size: int = DEFAULT_BUFF_SIZE, tcp_nodelay: bool = False) -> None:
        set_queue = queue_size is not None
        if queue_size == -1:
            queue_size = None
        elif queue_size == 0:
            raise ROSException("queue size may not be set to zero")
        elif set_queue and type(queue_size) is not int:
            raise ROSException("queue size must be an integer")
        if buff_size != DEFAULT_BUFF_SIZE:
            if type(buff_size) is not int:
                raise ROSException("buffer size must be an integer")
            if buff_size <= 0:
                raise ROSException("buffer size must be a positive integer")

        def configure(impl: Any) -> None:
            if set_queue:
                impl.queue_size = queue_size
            if buff_size != DEFAULT_BUFF_SIZE:
                impl.buff_size = buff_size
            if tcp_nodelay:
                impl.tcp_nodelay = True

        # a fresh subscription is set up before it is announced, so its first connections
        # already ask for tcp_nodelay; a shared one takes the settings as rospy's does
        super().__init__(name, data_class, configure=configure)
        impl = self.impl
        configure(impl)
        self.callback = callback
        self.callback_args = callback_args
        if callback is not None:
            impl.add_callback(callback, callback_args)

    def unregister(self) -> None:
        impl = self.impl
        if impl is not None and self.callback is not None:
            try:
                impl.remove_callback(self.callback, self.callback_args)
            except KeyError:
                pass
        self.callback = self.callback_args = None
        super().unregister()


# ---------------------------------------------------------------------------------------------
# helpers


def wait_for_message(topic: str, topic_type: Any, timeout: float | None = None) -> Any:
    """Subscribe to ``topic`` and return its next message (rospy.wait_for_message)."""
    if timeout is not None and hasattr(timeout, "to_sec"):
        timeout = timeout.to_sec()  # rospy accepts a Duration
    received: list = []
    event = threading.Event()

    def callback(msg: Any) -> None:
        if not received:
            received.append(msg)
            event.set()

    sub = Subscriber(topic, topic_type, callback)
    try:
        deadline = None if timeout is None else time.monotonic() + timeout
        while not event.is_set():
            if _node_mod.is_shutdown():
                raise ROSInterruptException("rospy shutdown")
            remaining = 0.01 if deadline is None else min(0.01, deadline - time.monotonic())
            if remaining <= 0:
                raise ROSException(f"timeout exceeded while waiting for message on topic {topic}")
            event.wait(remaining)
        return received[0]
    finally:
        sub.unregister()


def get_published_topics(namespace: str = "/") -> List[List[str]]:
    """[[topic, type], ...] published in ``namespace`` (master getPublishedTopics)."""
    try:
        return [list(pair) for pair in _node_mod.master().get_published_topics(namespace)]
    except RemoteError as exc:
        raise ROSException(f"unable to get published topics: {exc}") from None

