"""Topic statistics (rospy's ``/enable_statistics``): per-connection rosgraph_msgs/TopicStatistics
on ``/statistics``.

When the parameter ``/enable_statistics`` is true as a subscription is made, each of its
connections counts what it delivers (arrival times, bytes, header stamps and sequence gaps) and
publishes a TopicStatistics message when its window ends; the window starts at 1 s and doubles
or halves (between ``/statistics_window_min_size`` and ``/statistics_window_max_size`` seconds)
to hold between ``/statistics_window_min_elements`` and ``/statistics_window_max_elements``
messages, as in rospy. Off (the default), nothing is added: the receive loop wraps its deliver
function only for a subscription that has statistics.
"""

from __future__ import annotations

import math
import threading
from typing import Any, Callable, List

from minros import node as _node_mod
from minros.client import params, rostime, topics
from minros.client.log import logerr

__all__ = ["install", "SubscriberStatistics"]

#: topics never measured (as in rospy: the clock and the statistics themselves)
_SKIPPED = ("/clock", "/statistics")


def install() -> None:
    """Measure the subscriptions made from now on when ``/enable_statistics`` is true."""
    topics.statistics_factory = _factory


def _factory(impl: Any) -> SubscriberStatistics | None:
    if impl.resolved_name in _SKIPPED:
        return None
    try:
        enabled = bool(params.get_param("/enable_statistics", False))
    except Exception:  # noqa: BLE001 - no master answer: no statistics, as rospy
        return None
    return SubscriberStatistics(impl.resolved_name) if enabled else None


class SubscriberStatistics:
    """The statistics of one subscription: one :class:`ConnectionStatistics` per publisher."""

    def __init__(self, topic: str) -> None:
        self.topic = topic
        self.min_elements = int(params.get_param("/statistics_window_min_elements", 10))
        self.max_elements = int(params.get_param("/statistics_window_max_elements", 100))
        self.min_window = float(params.get_param("/statistics_window_min_size", 4))
        self.max_window = float(params.get_param("/statistics_window_max_size", 64))
        self._lock = threading.Lock()
        self._connections: List[ConnectionStatistics] = []

    def wrap(self, connection: Any, deliver: Callable[[Any], None]) -> Callable[[Any], None]:
        """``deliver`` preceded by this connection's accounting (the receive loop calls it)."""
        stats = ConnectionStatistics(self, connection)
        with self._lock:
            self._connections.append(stats)

        def deliver_measured(msg: Any) -> None:
            try:
                stats.record(msg)
            except Exception as exc:  # noqa: BLE001 - statistics never stop a delivery
                logerr(f"Unexpected error during statistics measurement: {exc}")
            deliver(msg)

        return deliver_measured

    def shutdown(self) -> None:
        with self._lock:
            connections, self._connections = self._connections, []
        for stats in connections:
            stats.shutdown()


class ConnectionStatistics:
    """What one publisher's connection delivered in the current window."""

    def __init__(self, owner: SubscriberStatistics, connection: Any) -> None:
        from rosgraph_msgs.msg import TopicStatistics

        self.owner = owner
        self.connection = connection
        self.message_class = TopicStatistics
        self.publisher = topics.Publisher("/statistics", TopicStatistics, queue_size=10)
        self.frequency = 1.0  # windows per second
        self.last_publish = 0.0
        self.window_start = rostime.get_rostime()
        self.arrivals: List[Any] = []
        self.ages: List[Any] = []
        self.last_seq = 0
        self.dropped = 0
        self.bytes_at_start = 0

    def record(self, msg: Any) -> None:
        now = rostime.get_rostime()
        self.arrivals.append(now)
        if getattr(msg, "_has_header", False):
            self.ages.append(now - msg.header.stamp)
            if self.last_seq + 1 != msg.header.seq:
                self.dropped += 1
            self.last_seq = msg.header.seq
        seconds = now.to_sec()
        if self.last_publish + 1.0 / self.frequency < seconds:
            self.last_publish = seconds
            self.publish(now)

    def publish(self, now: Any) -> None:
        Duration = rostime.Duration
        msg = self.message_class()
        msg.topic = self.owner.topic
        msg.node_sub = _node_mod.get_caller_id()
        msg.node_pub = self.connection.callerid_pub
        msg.window_start = self.window_start
        msg.window_stop = now
        stat_bytes = self.connection.stat_bytes
        msg.traffic = stat_bytes - self.bytes_at_start
        msg.delivered_msgs = len(self.arrivals)
        msg.dropped_msgs = self.dropped
        msg.stamp_age_mean, msg.stamp_age_stddev, msg.stamp_age_max = _spread(self.ages, Duration)
        periods = [b - a for a, b in zip(self.arrivals[:-1], self.arrivals[1:])]
        msg.period_mean, msg.period_stddev, msg.period_max = _spread(periods, Duration)
        self.publisher.publish(msg)
        window = 1.0 / self.frequency
        if len(self.arrivals) > self.owner.max_elements and window / 2 >= self.owner.min_window:
            self.frequency *= 2
        if len(self.arrivals) < self.owner.min_elements and window * 2 <= self.owner.max_window:
            self.frequency /= 2
        self.arrivals = []
        self.ages = []
        self.dropped = 0
        self.window_start = now
        self.bytes_at_start = stat_bytes

    def shutdown(self) -> None:
        self.publisher.unregister()


def _spread(values: List[Any], duration: Any) -> tuple:
    """(mean, standard deviation, maximum) of durations; zeros for none."""
    if not values:
        return duration(0), duration(0), duration(0)
    seconds = [v.to_sec() for v in values]
    mean = sum(seconds) / len(seconds)
    variance = sum((mean - s) ** 2 for s in seconds) / len(seconds)
    return duration.from_sec(mean), duration.from_sec(math.sqrt(variance)), max(values)
