"""How the bridge chooses ROS 2 QoS from ROS 1's terms and the other way, pure.

ROS 1 has two knobs: a publisher latches or not, and each end has a queue size. ROS 2 has
policies that must match between a writer and a reader (the writer's offer at least what the
reader requests: reliable >= best effort, transient local >= volatile). The rules:

* **ROS 1 -> ROS 2** (the bridge's ROS 2 publisher): reliable (TCPROS loses nothing unless a
  queue overflows; a reliable writer serves best-effort readers too); KEEP_LAST with the queue
  size as depth; a latched ROS 1 publisher makes it transient local with depth 1 (ROS 2's
  "latched" convention, and what a ROS 1 latched publisher keeps: its last message), except
  ``/tf_static``, whose many latched publishers each keep their own transforms (ros1_bridge
  makes it keep-all; here a depth of ``TF_STATIC_DEPTH``, bounded).
* **ROS 2 -> ROS 1** (the bridge's ROS 2 subscription): what every publisher offers, so it
  matches them all: reliable only if each offers reliable (else best effort, which matches
  both), transient local only if each offers it; depth the queue size. The bridge's ROS 1
  publisher latches when the subscription is transient local, with the queue size as
  ``queue_size``.
* An explicit ``qos`` (the configuration's) is used as it is for both ROS 2 endpoints; the ROS 1
  publisher latches when it says transient local. A publisher whose offer does not satisfy it
  does not match: the RTPS layer says so in one line naming the policy.
"""

from __future__ import annotations

from typing import Iterable, Optional

from minros.ros2.rmw.qos import QoSProfile

__all__ = ["TF_STATIC_DEPTH", "latches", "publisher_qos", "subscription_qos"]

#: the depth of the transient-local /tf_static publisher (ros1_bridge keeps all)
TF_STATIC_DEPTH = 100


def publisher_qos(topic: str, latched: bool, queue_size: int,
                  explicit: Optional[QoSProfile] = None) -> QoSProfile:
    """The QoS of the bridge's ROS 2 publisher for a ROS 1 topic."""
    if explicit is not None:
        return explicit
    if latched:
        depth = TF_STATIC_DEPTH if topic == "/tf_static" else 1
        return QoSProfile(depth=depth, durability="transient_local")
    return QoSProfile(depth=max(1, queue_size))


def subscription_qos(offered: Iterable[QoSProfile], queue_size: int,
                     explicit: Optional[QoSProfile] = None) -> QoSProfile:
    """The QoS of the bridge's ROS 2 subscription that matches every publisher ``offered``
    (reliable and volatile when there is none yet)."""
    if explicit is not None:
        return explicit
    offers = list(offered)
    reliable = all(q.reliability == "reliable" for q in offers)
    durable = bool(offers) and all(q.durability == "transient_local" for q in offers)
    return QoSProfile(reliability="reliable" if reliable else "best_effort",
                      durability="transient_local" if durable else "volatile",
                      depth=max(1, queue_size))


def latches(qos: QoSProfile) -> bool:
    """Whether the bridge's ROS 1 publisher fed by a subscription of ``qos`` latches."""
    return qos.durability == "transient_local"
