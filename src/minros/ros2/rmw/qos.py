"""ROS 2 QoS profiles as rclpy has them, and their DDS form.

rclpy's presets (``rclpy.qos``, rmw's ``qos_profiles.h``): the default (reliable, volatile,
keep-last 10), sensor data (best effort, keep-last 5), services (reliable, volatile,
keep-last 10), parameters (reliable, keep-last 1000) and the system default (what the DDS
gives: reliable, volatile, keep-last 1 here). A latched ROS 1 topic is
``QoSProfile(depth=1, durability="transient_local")``.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace
from typing import Dict

from minros.ros2.rtps import discovery as d

__all__ = ["DEFAULT", "PARAMETERS", "QoSProfile", "SENSOR_DATA", "SERVICES_DEFAULT",
           "SYSTEM_DEFAULT", "from_dds"]

_RELIABILITY: Dict[str, int] = {"reliable": d.RELIABLE, "best_effort": d.BEST_EFFORT}
_DURABILITY: Dict[str, int] = {"volatile": d.VOLATILE, "transient_local": d.TRANSIENT_LOCAL}
_HISTORY: Dict[str, int] = {"keep_last": d.KEEP_LAST, "keep_all": d.KEEP_ALL}
_LIVELINESS: Dict[str, int] = {"automatic": d.AUTOMATIC,
                               "manual_by_topic": d.MANUAL_BY_TOPIC}


@dataclass(frozen=True)
class QoSProfile:
    """A ROS 2 QoS profile: policies by rclpy's names, durations in seconds (``math.inf``:
    rmw's "infinite", which is also its default)."""

    reliability: str = "reliable"
    durability: str = "volatile"
    history: str = "keep_last"
    depth: int = 10
    deadline: float = math.inf
    lifespan: float = math.inf
    liveliness: str = "automatic"
    liveliness_lease_duration: float = math.inf
    avoid_ros_namespace_conventions: bool = False

    def __post_init__(self) -> None:
        for value, table, what in ((self.reliability, _RELIABILITY, "reliability"),
                                   (self.durability, _DURABILITY, "durability"),
                                   (self.history, _HISTORY, "history"),
                                   (self.liveliness, _LIVELINESS, "liveliness")):
            if value not in table:
                raise ValueError(f"{what} {value!r}: one of {', '.join(table)}")
        if self.history == "keep_last" and self.depth < 1:
            raise ValueError(f"depth {self.depth}: keep_last needs a depth of 1 or more")

    def with_(self, **changes: object) -> QoSProfile:
        return replace(self, **changes)  # type: ignore[arg-type]

    def to_dds(self) -> d.Qos:
        return d.Qos(reliability=_RELIABILITY[self.reliability],
                     durability=_DURABILITY[self.durability],
                     history=_HISTORY[self.history], depth=self.depth,
                     deadline=self.deadline, lifespan=self.lifespan,
                     liveliness=_LIVELINESS[self.liveliness],
                     lease_duration=self.liveliness_lease_duration)

    def describe(self) -> str:
        return self.to_dds().describe()


def from_dds(qos: d.Qos) -> QoSProfile:
    """A DDS endpoint's QoS in ROS 2's terms (what rclpy's ``get_publishers_info_by_topic``
    reports)."""
    return QoSProfile(
        reliability="reliable" if qos.reliability == d.RELIABLE else "best_effort",
        durability="transient_local" if qos.durability >= d.TRANSIENT_LOCAL else "volatile",
        history="keep_all" if qos.history == d.KEEP_ALL else "keep_last",
        # (a remote endpoint's history is not on the wire: the default's depth, 1, then)
        depth=max(qos.depth, 1),
        deadline=qos.deadline, lifespan=qos.lifespan,
        liveliness="manual_by_topic" if qos.liveliness == d.MANUAL_BY_TOPIC else "automatic",
        liveliness_lease_duration=qos.lease_duration)


DEFAULT = QoSProfile()
SENSOR_DATA = QoSProfile(reliability="best_effort", depth=5)
SERVICES_DEFAULT = QoSProfile()
PARAMETERS = QoSProfile(depth=1000)
SYSTEM_DEFAULT = QoSProfile(depth=1)
LATCHED = QoSProfile(depth=1, durability="transient_local")
