"""ROS 2 services on DDS, answering each vendor its own way.

A service is two topics (``rq/<name>Request``, ``rr/<name>Reply``): the server reads
requests and writes replies; every client writes requests and reads every reply, keeping its
own. How a client knows which reply is its own differs by rmw:

* **Fast DDS** (rmw_fastrtps) carries a request's identity out of band. The request is a
  plain sample whose identity is (its writer's GUID, its sequence number), with inline QoS
  ``PID_RELATED_SAMPLE_IDENTITY`` (0x0083) naming the client's *reply reader* (sequence
  number unknown). The server's reply carries ``PID_RELATED_SAMPLE_IDENTITY`` = (that reader's
  GUID, the request's sequence number), and the server waits, before writing it, until its
  reply writer has matched that reader (else the reply would go to nobody: readers are
  volatile). The client keeps replies whose related identity names its reader or writer.
* **Cyclone DDS** (rmw_cyclonedds) carries it in band: each request and reply payload starts,
  right after the encapsulation header, with ``cdds_request_header_t {uint64 guid; int64
  seq}`` (the client's id and a counter); the server copies it into the reply. Endpoints
  carry ``clientid=...;``/``serviceid=...;`` in USER_DATA so the server can wait for the
  client's reader, as above.

So a Fast DDS client and a Cyclone server (or the reverse) read each other's bytes wrong:
ROS 2's own cross-vendor calls fail (ros2/rmw_cyclonedds#184). minros looks at each peer's
vendor id (SPDP) and answers it in its own form: as a server it takes requests of both forms
and replies in the form each came in; as a client it sends the form its matched servers
speak (in band when they are all Cyclone, out of band otherwise: Fast DDS and minros) and
reads replies of both forms. minros peers use the out-of-band form.
"""

from __future__ import annotations

import itertools
import logging
import os
import queue
import struct
import threading
import time
from concurrent.futures import Future
from concurrent.futures import TimeoutError as FutureTimeout
from typing import Any, Callable, Dict, Optional, Set, Tuple, Union

from minros.ros2.rmw import names
from minros.ros2.rmw.names import type_hash_user_data
from minros.ros2.rmw.qos import QoSProfile
from minros.ros2.rtps import guid as g
from minros.ros2.rtps import params as p
from minros.ros2.rtps.endpoint import Sample
from minros.ros2.rtps.participant import LocalReader, LocalWriter

__all__ = ["Client", "Payload", "Service", "ServiceTimeout"]

log = logging.getLogger("minros.ros2")

Payload = Union[bytes, bytearray, memoryview]

#: how long a server waits for a client's reply reader to match before giving up on a reply
#: (rmw_fastrtps waits the writer's max_blocking_time, rmw_cyclonedds 100 ms)
REPLY_MATCH_TIMEOUT = 1.0
#: requests waiting for the handler; more are dropped (one log line)
MAX_QUEUED_REQUESTS = 1000
_CDDS_HEADER = struct.Struct("<Qq")


class ServiceTimeout(TimeoutError):
    """No reply came in time."""


def _related_identity(sample: Sample) -> Optional[Tuple[bytes, int]]:
    value = p.find(sample.inline_qos, sample.little, p.PID_RELATED_SAMPLE_IDENTITY)
    if value is None:
        return None
    return p.decode_sample_identity(value, sample.little)


class Service:
    """A service server: ``handler(request)`` gets the serialized request (CDR, encapsulation
    header first) and returns the serialized response, in the service's own thread; None
    sends no reply (a handler that cannot answer, as a bridge whose far server failed: the
    client's call times out, as with a server that is gone)."""

    def __init__(self, node: Any, name: str, srv_type: str,
                 handler: Callable[[bytes], Optional[Payload]], qos: QoSProfile,
                 request_hash: Optional[str], response_hash: Optional[str]) -> None:
        self.node = node
        self.name = name
        self.srv_type = srv_type
        self.handler = handler
        self.context = node.context
        part = self.context.participant
        request_topic, reply_topic = names.service_topics(
            name, qos.avoid_ros_namespace_conventions)
        request_type, reply_type = names.service_types(srv_type)
        self.service_id = os.urandom(8).hex()
        extra = f"serviceid={self.service_id};"
        self.reply_writer: LocalWriter = part.create_writer(
            reply_topic, reply_type, qos.to_dds(), user_data=type_hash_user_data(response_hash,
                                                                                 extra))
        self._queue: queue.Queue[Optional[Sample]] = queue.Queue(MAX_QUEUED_REQUESTS)
        self.request_reader: LocalReader = part.create_reader(
            request_topic, request_type, qos.to_dds(), self._on_request,
            user_data=type_hash_user_data(request_hash, extra))
        self.handled = 0
        self._dropped = False
        self._thread = threading.Thread(target=self._serve, name=f"minros-ros2-service:{name}",
                                        daemon=True)
        self._thread.start()
        for ep in (self.reply_writer, self.request_reader):
            self.context.graph.add_endpoint(ep.data, local=True)
        node._register(self, [self.request_reader.guid], [self.reply_writer.guid])

    def _on_request(self, sample: Sample) -> None:
        try:
            self._queue.put_nowait(sample)
        except queue.Full:
            if not self._dropped:
                self._dropped = True
                log.warning("ROS 2 service %s: %d requests wait for the handler; dropping "
                            "new ones", self.name, MAX_QUEUED_REQUESTS)

    def _serve(self) -> None:
        while True:
            sample = self._queue.get()
            if sample is None:
                return
            try:
                self._answer(sample)
            except Exception:
                log.exception("ROS 2 service %s: the handler failed; no reply sent", self.name)

    def _answer(self, sample: Sample) -> None:
        vendor = self.context.vendor(sample.writer[:12])
        payload = bytes(sample.payload)
        if vendor == g.VENDOR_CYCLONE:
            if len(payload) < 4 + _CDDS_HEADER.size:
                log.warning("ROS 2 service %s: a request from %s without its Cyclone header",
                            self.name, g.guid_text(sample.writer))
                return
            header = payload[4:4 + _CDDS_HEADER.size]
            answer = self.handler(payload[:4] + payload[4 + _CDDS_HEADER.size:])
            self.handled += 1
            if answer is None:
                return  # the handler chose not to answer (it said why)
            response = bytes(answer)
            if not self._wait_for_cyclone_client(sample.writer):
                log.warning("ROS 2 service %s: the reply reader of client %s did not match "
                            "within %g s; its reply is dropped", self.name,
                            g.guid_text(sample.writer), REPLY_MATCH_TIMEOUT)
                return
            self.reply_writer.write(response[:4] + header + response[4:])
            return
        related = _related_identity(sample)
        target = sample.writer
        if related is not None and related[0] != g.GUID_UNKNOWN:
            target = related[0]
        answer = self.handler(payload)
        self.handled += 1
        if answer is None:
            return  # the handler chose not to answer (it said why)
        response = bytes(answer)
        if g.is_reader(target[12:]) and not self.reply_writer.wait_matched(
                target, REPLY_MATCH_TIMEOUT):
            log.warning("ROS 2 service %s: the reply reader %s did not match within %g s; its "
                        "reply is dropped", self.name, g.guid_text(target), REPLY_MATCH_TIMEOUT)
            return
        identity = p.ParamWriter().add(p.PID_RELATED_SAMPLE_IDENTITY,
                                       p.sample_identity(target, sample.sn)).encode()
        self.reply_writer.write(response, inline_qos=identity)

    def _wait_for_cyclone_client(self, request_writer: bytes) -> bool:
        """rmw_cyclonedds's rule: wait until a matched reply reader has the client's id."""
        part = self.context.participant
        data = next((e for e in part.remote_endpoints() if e.guid == request_writer), None)
        client_id = data.user_data_value("clientid") if data is not None else None
        if client_id is None:
            return True  # an older client without an id: as rmw_cyclonedds, assume it is there
        writer = self.reply_writer
        deadline = time.monotonic() + REPLY_MATCH_TIMEOUT
        with writer.lock:
            while True:
                if any(e.user_data_value("clientid") == client_id
                       for e in writer.matched.values()):
                    return True
                left = deadline - time.monotonic()
                if left <= 0 or writer.closed:
                    return False
                writer.changed.wait(left)

    def destroy(self) -> None:
        part = self.context.participant
        part.delete(self.request_reader)
        part.delete(self.reply_writer)
        self._queue.put(None)
        for ep in (self.reply_writer, self.request_reader):
            self.context.graph.remove_endpoint(ep.guid)
        self.node._unregister(self, [self.request_reader.guid], [self.reply_writer.guid])


class Client:
    """A service client: :meth:`call` sends a serialized request and returns the response."""

    def __init__(self, node: Any, name: str, srv_type: str, qos: QoSProfile,
                 request_hash: Optional[str], response_hash: Optional[str]) -> None:
        self.node = node
        self.name = name
        self.srv_type = srv_type
        self.context = node.context
        part = self.context.participant
        request_topic, reply_topic = names.service_topics(
            name, qos.avoid_ros_namespace_conventions)
        request_type, reply_type = names.service_types(srv_type)
        raw = os.urandom(8)
        #: the 64-bit id Cyclone's in-band header carries
        self.client_id = int.from_bytes(raw, "little")
        extra = f"clientid={raw.hex()};"
        self._lock = threading.Lock()
        self._pending: Dict[Tuple[str, int], Future[bytes]] = {}
        self._seq = itertools.count(1)
        self.reply_reader: LocalReader = part.create_reader(
            reply_topic, reply_type, qos.to_dds(), self._on_reply,
            user_data=type_hash_user_data(response_hash, extra))
        self.request_writer: LocalWriter = part.create_writer(
            request_topic, request_type, qos.to_dds(),
            user_data=type_hash_user_data(request_hash, extra))
        for ep in (self.request_writer, self.reply_reader):
            self.context.graph.add_endpoint(ep.data, local=True)
        node._register(self, [self.reply_reader.guid], [self.request_writer.guid])

    # -- availability ------------------------------------------------------------------------

    def service_is_ready(self) -> bool:
        """A server's request reader matched this client's writer and its reply writer this
        client's reader (both servers, Fast DDS's and Cyclone's, wait for their reply writer
        to match the client's reader before they reply)."""
        return self.request_writer.matched_count() > 0 and self.reply_reader.matched_count() > 0

    def wait_for_service(self, timeout: float = 5.0) -> bool:
        deadline = time.monotonic() + timeout
        graph = self.context.graph
        version = graph.version
        while not self.service_is_ready():
            left = deadline - time.monotonic()
            if left <= 0:
                return False
            version = graph.wait_for_change(version, left)
        return True

    # -- calls -------------------------------------------------------------------------------

    def _server_vendors(self) -> Set[bytes]:
        with self.request_writer.lock:
            prefixes = {guid[:12] for guid in self.request_writer.matched}
        return {self.context.vendor(prefix) for prefix in prefixes}

    def call_async(self, request: Payload) -> Future[bytes]:
        """Send ``request``; the future's result is the serialized response."""
        future: Future[bytes] = Future()
        vendors = self._server_vendors()
        if vendors and vendors == {g.VENDOR_CYCLONE}:
            seq = next(self._seq)
            body = bytes(request)
            with self._lock:
                self._pending[("cyclone", seq)] = future
            self.request_writer.write(body[:4] + _CDDS_HEADER.pack(self.client_id, seq) + body[4:])
            return future
        identity = p.ParamWriter().add(
            p.PID_RELATED_SAMPLE_IDENTITY,
            p.sample_identity(self.reply_reader.guid, -(1 << 32))).encode()
        with self._lock:
            # the sequence number is the writer's next one: reserve it before the reply can come
            sn = self.request_writer.machine.last_sn + 1
            self._pending[("fast", sn)] = future
            written = self.request_writer.write(request, inline_qos=identity)
            if written != sn:  # another thread wrote in between: re-key
                self._pending[("fast", written)] = self._pending.pop(("fast", sn))
        return future

    def call(self, request: Payload, timeout: float = 5.0) -> bytes:
        """Send ``request`` and wait for the response; ServiceTimeout after ``timeout``."""
        future = self.call_async(request)
        try:
            return future.result(timeout)
        except FutureTimeout:
            with self._lock:
                for key, value in list(self._pending.items()):
                    if value is future:
                        del self._pending[key]
            raise ServiceTimeout(f"service {self.name}: no reply within {timeout:g} s") from None

    def _on_reply(self, sample: Sample) -> None:
        key: Optional[Tuple[str, int]] = None
        payload = bytes(sample.payload)
        related = _related_identity(sample)
        if related is not None and related[0] in (self.reply_reader.guid,
                                                  self.request_writer.guid):
            key = ("fast", related[1])
        elif related is None and self.context.vendor(sample.writer[:12]) == g.VENDOR_CYCLONE \
                and len(payload) >= 4 + _CDDS_HEADER.size:
            client_id, seq = _CDDS_HEADER.unpack_from(payload, 4)
            if client_id == self.client_id:
                key = ("cyclone", seq)
                payload = payload[:4] + payload[4 + _CDDS_HEADER.size:]
        if key is None:
            return  # another client's reply
        with self._lock:
            future = self._pending.pop(key, None)
        if future is not None and not future.done():
            future.set_result(payload)

    def destroy(self) -> None:
        part = self.context.participant
        part.delete(self.request_writer)
        part.delete(self.reply_reader)
        for ep in (self.request_writer, self.reply_reader):
            self.context.graph.remove_endpoint(ep.guid)
        with self._lock:
            for future in self._pending.values():
                future.cancel()
            self._pending.clear()
        self.node._unregister(self, [self.reply_reader.guid], [self.request_writer.guid])
