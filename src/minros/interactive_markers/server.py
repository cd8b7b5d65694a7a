"""InteractiveMarkerServer: markers kept here, changes published in batches."""

from __future__ import annotations

import copy
import threading
from typing import Any, Callable, Dict, Optional

import minros
from visualization_msgs.msg import (
    InteractiveMarker,
    InteractiveMarkerFeedback,
    InteractiveMarkerInit,
    InteractiveMarkerPose,
    InteractiveMarkerUpdate,
)

__all__ = ["InteractiveMarkerServer", "MarkerContext", "UpdateContext"]

FeedbackCallback = Callable[[Any], None]
#: feedback from a second client is ignored while another one moved the marker this recently
CLIENT_LOCK_SECONDS = 1.0


class MarkerContext:
    """A published marker and the callbacks its feedback goes to."""

    def __init__(self) -> None:
        self.last_feedback = minros.Time.now()
        self.last_client_id = ""
        self.default_feedback_cb: Optional[FeedbackCallback] = None
        self.feedback_cbs: Dict[int, FeedbackCallback] = {}
        self.int_marker = InteractiveMarker()


class UpdateContext:
    """A change waiting for ``applyChanges()``."""

    FULL_UPDATE = 0
    POSE_UPDATE = 1
    ERASE = 2

    def __init__(self) -> None:
        self.update_type = self.FULL_UPDATE
        self.int_marker = InteractiveMarker()
        self.default_feedback_cb: Optional[FeedbackCallback] = None
        self.feedback_cbs: Dict[int, FeedbackCallback] = {}


class InteractiveMarkerServer:
    """A server of interactive markers under ``topic_ns``; ``server_id`` is appended to the
    node's name to tell this server's messages from another's on the same topics."""

    DEFAULT_FEEDBACK_CB = 255

    def __init__(self, topic_ns: str, server_id: str = "", q_size: int = 100) -> None:
        self.topic_ns = topic_ns
        self.seq_num = 0
        self.mutex = threading.RLock()
        self.server_id = minros.get_name() + server_id
        self.marker_contexts: Dict[str, MarkerContext] = {}
        self.pending_updates: Dict[str, UpdateContext] = {}
        self.init_pub = minros.Publisher(topic_ns + "/update_full", InteractiveMarkerInit,
                                         latch=True, queue_size=100)
        self.update_pub = minros.Publisher(topic_ns + "/update", InteractiveMarkerUpdate,
                                           queue_size=100)
        self.feedback_sub = minros.Subscriber(topic_ns + "/feedback", InteractiveMarkerFeedback,
                                              self.processFeedback, queue_size=q_size)
        self.keep_alive_timer = minros.Timer(minros.Duration(0.5), self.keepAlive)
        self.publishInit()

    # markers
    def insert(self, marker: Any, feedback_cb: Any = -1,
               feedback_type: int = DEFAULT_FEEDBACK_CB) -> None:
        """Add or replace ``marker`` (published at the next applyChanges); a callback given
        here is set as with :meth:`setCallback`."""
        with self.mutex:
            update = self.pending_updates.setdefault(marker.name, UpdateContext())
            update.update_type = UpdateContext.FULL_UPDATE
            update.int_marker = marker
        if feedback_cb != -1:
            self.setCallback(marker.name, feedback_cb, feedback_type)

    def setPose(self, name: str, pose: Any, header: Any = None) -> bool:
        """Move a marker; an empty ``header.frame_id`` keeps the marker's frame. False when
        there is no such marker (or it was just inserted: insert it with the pose)."""
        with self.mutex:
            context = self.marker_contexts.get(name)
            update = self.pending_updates.get(name)
            if context is None and update is None:
                return False
            if update is not None and update.update_type == UpdateContext.FULL_UPDATE:
                return False
            if header is None or not header.frame_id:
                if context is None:
                    return False
                header = context.int_marker.header
            self._doSetPose(update, name, pose, header)
            return True

    def erase(self, name: str) -> bool:
        with self.mutex:
            if name in self.pending_updates:
                self.pending_updates[name].update_type = UpdateContext.ERASE
                return True
            if name in self.marker_contexts:
                update = UpdateContext()
                update.update_type = UpdateContext.ERASE
                self.pending_updates[name] = update
                return True
            return False

    def clear(self) -> None:
        """Erase every marker (at the next applyChanges)."""
        with self.mutex:
            self.pending_updates = {}
            for name in list(self.marker_contexts):
                self.erase(name)

    def empty(self) -> bool:
        with self.mutex:
            return not self.marker_contexts

    def size(self) -> int:
        with self.mutex:
            return len(self.marker_contexts)

    def setCallback(self, name: str, feedback_cb: Optional[FeedbackCallback],
                    feedback_type: int = DEFAULT_FEEDBACK_CB) -> bool:
        """Route feedback of ``feedback_type`` (an InteractiveMarkerFeedback event type, or
        every type without a callback of its own) for marker ``name``; None removes it."""
        with self.mutex:
            targets = [t for t in (self.marker_contexts.get(name), self.pending_updates.get(name))
                       if t is not None]
            if not targets:
                return False
            for target in targets:
                if feedback_type == self.DEFAULT_FEEDBACK_CB:
                    target.default_feedback_cb = feedback_cb
                elif feedback_cb is not None:
                    target.feedback_cbs[feedback_type] = feedback_cb
                else:
                    target.feedback_cbs.pop(feedback_type, None)
            return True

    def applyChanges(self) -> None:
        """Publish the pending changes as one update, then the new full state."""
        with self.mutex:
            if not self.pending_updates:
                return
            update_msg = InteractiveMarkerUpdate(type=InteractiveMarkerUpdate.UPDATE)
            for name, update in self.pending_updates.items():
                if update.update_type == UpdateContext.FULL_UPDATE:
                    context = self.marker_contexts.get(name)
                    if context is None:
                        context = MarkerContext()
                        context.default_feedback_cb = update.default_feedback_cb
                        context.feedback_cbs = update.feedback_cbs
                        self.marker_contexts[name] = context
                    context.int_marker = update.int_marker
                    update_msg.markers.append(context.int_marker)
                elif update.update_type == UpdateContext.POSE_UPDATE:
                    context = self.marker_contexts.get(name)
                    if context is None:
                        minros.logerr("Pending pose update for non-existing marker found. This "
                                      "is a bug in InteractiveMarkerInterface.")
                        continue
                    context.int_marker.pose = update.int_marker.pose
                    context.int_marker.header = update.int_marker.header
                    update_msg.poses.append(InteractiveMarkerPose(
                        header=context.int_marker.header, pose=context.int_marker.pose,
                        name=name))
                elif self.marker_contexts.pop(name, None) is not None:  # ERASE
                    update_msg.erases.append(name)
            self.pending_updates = {}
            self.seq_num += 1
            self._publish(update_msg)
            self.publishInit()

    def get(self, name: str) -> Any:
        """The marker as it will be after the pending changes (None if erased or unknown)."""
        with self.mutex:
            update = self.pending_updates.get(name)
            context = self.marker_contexts.get(name)
            if update is None:
                return context.int_marker if context is not None else None
            if update.update_type == UpdateContext.ERASE:
                return None
            if update.update_type == UpdateContext.POSE_UPDATE:
                if context is None:
                    return None
                marker = copy.copy(context.int_marker)
                marker.pose = update.int_marker.pose
                return marker
            return update.int_marker

    # protocol
    def processFeedback(self, feedback: Any) -> None:
        with self.mutex:
            context = self.marker_contexts.get(feedback.marker_name)
            if context is None:
                return
            now = minros.Time.now()
            if context.last_client_id != feedback.client_id and \
                    (now - context.last_feedback).to_sec() < CLIENT_LOCK_SECONDS:
                minros.logdebug(f"Rejecting feedback for {feedback.marker_name}: conflicting "
                                "feedback from separate clients.")
                return
            context.last_feedback = now
            context.last_client_id = feedback.client_id
            if feedback.event_type == InteractiveMarkerFeedback.POSE_UPDATE:
                # a marker without a stamp follows its frame: keep the marker's header
                stamped = context.int_marker.header.stamp != minros.Time()
                header = feedback.header if stamped else context.int_marker.header
                self._doSetPose(self.pending_updates.get(feedback.marker_name),
                                feedback.marker_name, feedback.pose, header)
            callback = context.feedback_cbs.get(feedback.event_type, context.default_feedback_cb)
        if callback is not None:
            callback(feedback)

    def keepAlive(self, event: Any = None) -> None:
        with self.mutex:
            self._publish(InteractiveMarkerUpdate(type=InteractiveMarkerUpdate.KEEP_ALIVE))

    def _publish(self, update: Any) -> None:
        update.server_id = self.server_id
        update.seq_num = self.seq_num
        self.update_pub.publish(update)

    def publishInit(self) -> None:
        with self.mutex:
            self.init_pub.publish(InteractiveMarkerInit(
                server_id=self.server_id, seq_num=self.seq_num,
                markers=[c.int_marker for c in self.marker_contexts.values()]))

    def _doSetPose(self, update: Optional[UpdateContext], name: str, pose: Any,
                   header: Any) -> None:
        if update is None:
            update = UpdateContext()
            update.update_type = UpdateContext.POSE_UPDATE
            self.pending_updates[name] = update
        elif update.update_type != UpdateContext.FULL_UPDATE:
            update.update_type = UpdateContext.POSE_UPDATE
        update.int_marker.pose = pose
        update.int_marker.header = header

    def shutdown(self) -> None:
        """Stop the keep-alive and close the topics."""
        self.keep_alive_timer.shutdown()
        for endpoint in (self.feedback_sub, self.update_pub, self.init_pub):
            endpoint.unregister()


