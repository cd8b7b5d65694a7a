"""TFRepublisher: the action and the service of tf2_web_republisher over one tf2 Buffer."""

from __future__ import annotations

import itertools
import threading
import time
from typing import Any, Dict, List

import minros
from minros.actionlib import ActionServer
from minros.tf.exceptions import TransformException
from minros.tf2_web_republisher.pairs import TFPair
from tf2_web_republisher.msg import TFArray, TFSubscriptionAction, TFSubscriptionFeedback
from tf2_web_republisher.srv import RepublishTFs, RepublishTFsResponse

__all__ = ["TFRepublisher"]

#: a rate below this (or not a number) is refused: it would make a timer of hours
MIN_RATE = 0.01


class _Client:
    def __init__(self, client_id: int, pairs: List[TFPair]) -> None:
        self.client_id = client_id
        self.pairs = pairs
        self.timer: Any = None


class TFRepublisher:
    """Serve ``buffer``'s transforms on the action ``name`` and the ``republish_tfs``
    service (in the node's namespace), each client at its own rate."""

    def __init__(self, buffer: Any, name: str) -> None:
        self.buffer = buffer
        self.lock = threading.Lock()
        self.ids = itertools.count()
        self.goals: Dict[Any, _Client] = {}
        self.requests: List[_Client] = []
        self.server = ActionServer(name, TFSubscriptionAction, self.goal_cb, self.cancel_cb,
                                   auto_start=False)
        self.service = minros.Service("republish_tfs", RepublishTFs, self.request_cb)
        self.server.start()

    @staticmethod
    def _pairs(source_frames: List[str], target_frame: str, angular_thres: float,
               trans_thres: float) -> List[TFPair]:
        return [TFPair(source, target_frame, angular_thres, trans_thres) for source in source_frames]

    @staticmethod
    def _period(rate: float) -> float:
        if not rate >= MIN_RATE:
            raise ValueError(f"rate must be at least {MIN_RATE} Hz, not {rate}")
        return 1.0 / rate

    def _updates(self, pairs: List[TFPair]) -> List[Any]:
        """The transforms of ``pairs`` worth sending now."""
        out = []
        for pair in pairs:
            try:
                transform = self.buffer.lookup_transform(pair.target_frame, pair.source_frame,
                                                         minros.Time(0))
            except TransformException as exc:
                if pair.is_okay:
                    pair.is_okay = False
                    minros.logerr(str(exc))
                continue  # ROS's sends an identity transform here; nothing is better
            if not pair.is_okay:
                pair.is_okay = True
                minros.loginfo(f"Transform from {pair.source_frame} to {pair.target_frame} is "
                               f"working again at time {transform.header.stamp.to_sec()}")
            t, r = transform.transform.translation, transform.transform.rotation
            pair.update((t.x, t.y, t.z), (r.x, r.y, r.z, r.w))
            if pair.update_needed():
                transform.header.stamp = minros.Time.now()
                transform.header.frame_id = pair.target_frame
                transform.child_frame_id = pair.source_frame
                pair.transmitted_now()
                out.append(transform)
        return out

    # the action (roslibjs's TFClient)
    def goal_cb(self, gh: Any) -> None:
        goal = gh.get_goal()
        try:
            period = self._period(goal.rate)
        except ValueError as exc:
            gh.set_rejected(text=str(exc))
            return
        gh.set_accepted()
        client = _Client(next(self.ids), self._pairs(list(goal.source_frames), goal.target_frame,
                                                     goal.angular_thres, goal.trans_thres))

        def tick(event: Any) -> None:
            transforms = self._updates(client.pairs)
            if transforms:
                gh.publish_feedback(TFSubscriptionFeedback(transforms=transforms))

        client.timer = minros.Timer(minros.Duration.from_sec(period), tick)
        with self.lock:
            self.goals[gh] = client

    def cancel_cb(self, gh: Any) -> None:
        with self.lock:
            client = self.goals.pop(gh, None)
        if client is not None:
            client.timer.shutdown()
            gh.set_canceled()

    # the service (roslibpy's TFClient)
    def request_cb(self, req: Any) -> Any:
        try:
            period = self._period(req.rate)
        except ValueError as exc:
            raise minros.ServiceException(str(exc)) from None
        client = _Client(next(self.ids), self._pairs(list(req.source_frames), req.target_frame,
                                                     req.angular_thres, req.trans_thres))
        pub = minros.Publisher(f"~tf_repub_{client.client_id}", TFArray, queue_size=10,
                               latch=True)
        timeout = req.timeout.to_sec()
        unsubscribed_since = [time.monotonic()]

        def tick(event: Any) -> None:
            if pub.get_num_connections() > 0:
                unsubscribed_since[0] = time.monotonic()
            elif time.monotonic() - unsubscribed_since[0] >= timeout:
                minros.loginfo(f"No subscribers on tf topic for request {client.client_id} for "
                               f"{timeout:g} seconds. Unadvertising topic:{pub.resolved_name}")
                client.timer.shutdown()
                pub.unregister()
                with self.lock:
                    if client in self.requests:
                        self.requests.remove(client)
                return
            transforms = self._updates(client.pairs)
            if transforms:
                pub.publish(TFArray(transforms=transforms))

        client.timer = minros.Timer(minros.Duration.from_sec(period), tick)
        with self.lock:
            self.requests.append(client)
        minros.loginfo(f"Publishing requested TFs on topic {pub.resolved_name}")
        return RepublishTFsResponse(topic_name=pub.resolved_name)
