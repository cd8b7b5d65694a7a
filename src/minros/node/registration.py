"""A node's registrations with the master: made, redone after a master restart, undone at once
(rospy's registration.py, RegManager).

Every registration of the node goes through here, so all of them can be redone when the
master restarts (a probe thread asks ``getPid`` every second and notices another pid or a lost
contact) and undone with one ``system.multicall`` on shutdown. ``lock`` serialises the
exchanges with the master (the one lock held across a call out): a shutdown waits for a
registration in flight, so the master never sees the unregistration first.
"""

from __future__ import annotations

import logging
import threading
from typing import Any, Callable, Dict, List

from minros.node.lifecycle import Lifecycle
from minros.node.registries import Publication, Registries, Subscription
from minros.wire.masterapi import MasterClient, MasterIOError, RemoteError

__all__ = ["Registration"]

#: how often the master is probed to notice that it restarted
MASTER_PROBE_INTERVAL = 1.0
#: a registration the master did not answer is retried this often
REGISTER_RETRY = 0.2
#: seconds close() waits for a registration in flight before it unregisters everything
CLOSE_REGISTRATION_WAIT = 2.0

_logger = logging.getLogger("minros.node")
#: what the user sees (console and /rosout once the client library's logging is up)
_rosout = logging.getLogger("rosout")


class Registration:
    """The registrations of one node with its master (``master``, as the node).

    ``node_uri()`` is the node's slave API URI and ``rosrpc_uri()`` its services' URI."""

    def __init__(self, master: MasterClient, registries: Registries, lifecycle: Lifecycle,
                 node_uri: Callable[[], str | None], rosrpc_uri: Callable[[], str]) -> None:
        self.master = master
        self.registries = registries
        self.lifecycle = lifecycle
        self.node_uri = node_uri
        self.rosrpc_uri = rosrpc_uri
        self.lock = threading.Lock()
        #: True from start(): registrations go to the master from then on
        self.started = False
        #: set by close(): nothing is registered any more
        self.closed = threading.Event()
        self._master_pid: int | None = None
        self._master_lost = False
        self._warned = False

    # -- one registration at a time ----------------------------------------------------------

    def announce_publication(self, pub: Publication) -> None:
        topic, type_ = pub.resolved_name, pub.type
        self._announce("pub", topic, lambda: self._register_publisher(topic, type_))

    def announce_subscription(self, sub: Subscription) -> None:
        topic, type_ = sub.resolved_name, sub.type
        self._announce("sub", topic, lambda: self._register_subscriber(topic, type_))

    def announce_service(self, service: str) -> None:
        self._announce("srv", service, lambda: self._register_service(service))

    def withdraw_publication(self, topic: str) -> None:
        self._withdraw("pub", topic, lambda: self.master.unregister_publisher(topic, self._uri()))

    def withdraw_subscription(self, topic: str) -> None:
        self._withdraw("sub", topic, lambda: self.master.unregister_subscriber(topic, self._uri()))

    def withdraw_service(self, service: str) -> None:
        self._withdraw("srv", service,
                       lambda: self.master.unregister_service(service, self.rosrpc_uri()))

    def subscribe_param(self, key: str) -> Any:
        """subscribeParam: the current value (``{}`` when unset); RemoteError if refused."""
        self.registries.add_param_subscription(key)
        return self.master.subscribe_param(self._uri(), key)

    def _uri(self) -> str:
        return self.node_uri() or ""

    def _announce(self, kind: str, name: str, call: Callable[[], None]) -> None:
        """Run one registration call (nothing before start(): it registers everything); on a
        master failure the probe thread redoes all of them later."""
        if not self.started:
            return
        try:
            with self.lock:
                if self.closed.is_set():
                    return  # close() has unregistered what it found: this would outlive the node
                call()
        except Exception as exc:
            self._master_lost = True
            _logger.warning("cannot register %s [%s] with the master now (%s); will retry",
                            kind, name, exc)

    def _withdraw(self, kind: str, name: str, call: Callable[[], Any]) -> None:
        """One unregistration call (none once shutdown started: the multicall does them all)."""
        if not self.started or self.lifecycle.is_shutdown_requested():
            return
        try:
            call()
        except Exception as exc:
            _logger.warning("cannot unregister %s [%s]: %s", kind, name, exc)

    def _register_publisher(self, topic: str, type_: str) -> None:
        try:
            self.master.register_publisher(topic, type_, self._uri())
        except RemoteError as exc:
            _refused("pub", topic, exc)

    def _register_subscriber(self, topic: str, type_: str) -> None:
        try:
            publishers = self.master.register_subscriber(topic, type_, self._uri())
        except RemoteError as exc:
            _refused("sub", topic, exc)
            return
        sub = self.registries.subscriptions.get(topic)
        if sub is not None:
            sub.publisher_update(publishers)

    def _register_service(self, service: str) -> None:
        try:
            self.master.register_service(service, self.rosrpc_uri(), self._uri())
        except RemoteError as exc:
            _refused("srv", service, exc)

    def _resubscribe_param(self, key: str) -> None:
        try:
            value = self.master.subscribe_param(self._uri(), key)
        except RemoteError as exc:
            _refused("param", key, exc)
            return
        for handler in self.registries.param_update_handlers():
            try:
                handler(key, value)
            except Exception:
                _logger.debug("paramUpdate handler failed", exc_info=True)

    # -- all of them -------------------------------------------------------------------------

    def register_all(self, first: bool = False) -> None:
        """Register every publication, subscription, service and parameter subscription,
        retrying every REGISTER_RETRY seconds until the master answers."""
        while not self.lifecycle.is_shutdown_requested():
            try:
                with self.lock:
                    try:
                        pid: int | None = self.master.get_pid()
                    except RemoteError:
                        pid = None
                    pubs, subs, services, params = self.registries.snapshot()
                    for topic, type_ in pubs:
                        self._register_publisher(topic, type_)
                    for topic, type_ in subs:
                        self._register_subscriber(topic, type_)
                    for service in services:
                        self._register_service(service)
                    for key in params:
                        self._resubscribe_param(key)
                    self._master_pid = pid
                    self._master_lost = False
                    if not first:
                        _logger.info("re-registered with the master at %s", self.master.uri)
                return
            except Exception as exc:
                if not self._warned:
                    self._warned = True
                    text = (f"Unable to immediately register with master node [{self.master.uri}]: "
                            "master may not be running yet. Will keep trying.")
                    if isinstance(exc, MasterIOError) and exc.errcode == 403:
                        # not "may not be running": it runs and refuses us (ROS_ALLOWED_HOSTS)
                        text = (f"The master [{self.master.uri}] refuses this node: {exc.errmsg}. "
                                "Will keep trying.")
                    if first:
                        _rosout.error(text)
                    else:
                        _logger.error(text)
                _logger.debug("registration failed: %s", exc)
                if self.lifecycle.wait_for_shutdown(REGISTER_RETRY):
                    return

    def start_probe(self) -> None:
        threading.Thread(target=self._probe, name="minros-master-probe", daemon=True).start()

    def _probe(self) -> None:
        """Probe the master every second; re-register after it restarted or came back."""
        probe = self.master.with_timeout(2.0)
        while not self.lifecycle.wait_for_shutdown(MASTER_PROBE_INTERVAL):
            if self.closed.is_set():
                return
            pid: int | None
            try:
                pid = probe.get_pid()
            except MasterIOError:
                if not self._master_lost:
                    _logger.warning("lost contact with the master at %s", self.master.uri)
                self._master_lost = True
                continue
            except RemoteError:
                pid = self._master_pid
            if self._master_lost or pid != self._master_pid:
                self._warned = True
                self.register_all()

    def unregister_all(self, served_uri: Callable[[], str | None]) -> None:
        """close(): undo every registration with one multicall (after any registration in
        flight, for at most CLOSE_REGISTRATION_WAIT seconds); nothing is registered after.
        ``served_uri()`` is the services' URI, None when the node serves none; asked after the
        registration in flight, which may be the first service's (seen: a Ctrl-C while rospy
        registered the logger services left them registered)."""
        if self.closed.is_set():
            return
        self.closed.set()
        if not self.started:
            return
        # after any registration in flight (a Ctrl-C in the middle of rospy.Subscriber(...)):
        # the master must see it before the unregistration, or it outlives the node there.
        # Bounded: a registration stuck on a frozen master must not hold up the shutdown.
        locked = self.lock.acquire(timeout=CLOSE_REGISTRATION_WAIT)
        try:
            calls = self._unregistration_calls(served_uri())
            if calls:
                # tried even when the probe lost the master: a master that was only slow for a
                # moment would otherwise keep our registrations forever; one that is gone costs
                # a short wait
                try:
                    self.master.with_timeout(0.5 if self._master_lost else 2.0).multicall(calls)
                except Exception as exc:
                    _logger.warning("unregistration from the master failed: %s", exc)
        finally:
            if locked:
                self.lock.release()

    def _unregistration_calls(self, rosrpc_uri: str | None) -> List[Dict[str, Any]]:
        """Every unregistration, as one system.multicall's call list."""
        me, uri = self.master.caller_id, self._uri()
        pubs, subs, services, params = self.registries.snapshot()
        calls = [{"methodName": "unregisterSubscriber", "params": [me, t, uri]} for t, _ in subs]
        calls += [{"methodName": "unregisterPublisher", "params": [me, t, uri]} for t, _ in pubs]
        if rosrpc_uri is not None:
            calls += [{"methodName": "unregisterService", "params": [me, s, rosrpc_uri]}
                      for s in services]
        calls += [{"methodName": "unsubscribeParam", "params": [me, uri, k]} for k in params]
        return calls


def _refused(kind: str, name: str, exc: RemoteError) -> None:
    _logger.error("master refused to register %s [%s]: %s", kind, name, exc)
