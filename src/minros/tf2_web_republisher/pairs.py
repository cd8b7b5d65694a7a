"""One subscribed transform (source frame in target frame) and when it is worth sending."""

from __future__ import annotations

import math
from typing import Optional, Tuple

Vec = Tuple[float, float, float]
Quat = Tuple[float, float, float, float]


def clean_frame(frame_id: str) -> str:
    """tf2 frame names have no leading slash (web clients may still send one)."""
    return frame_id[1:] if frame_id.startswith("/") else frame_id


def rotation_angle(a: Quat, b: Quat) -> float:
    """The angle tf's ``Quaternion::angle`` measures between two rotations (acos of the
    normalized dot product: half the rotation between them)."""
    norm = math.sqrt(sum(x * x for x in a) * sum(x * x for x in b))
    if norm == 0.0:
        return 0.0
    dot = sum(x * y for x, y in zip(a, b)) / norm
    return math.acos(max(-1.0, min(1.0, dot)))


class TFPair:
    """Sends the first transform, then one that moved more than ``trans_thres`` metres or
    turned more than ``angular_thres`` (a zero threshold sends every update)."""

    def __init__(self, source_frame: str, target_frame: str, angular_thres: float = 0.0,
                 trans_thres: float = 0.0) -> None:
        self.source_frame = clean_frame(source_frame)
        self.target_frame = clean_frame(target_frame)
        self.angular_thres = angular_thres
        self.trans_thres = trans_thres
        self.received: Optional[Tuple[Vec, Quat]] = None
        self.transmitted: Optional[Tuple[Vec, Quat]] = None
        self.updated = False
        self.is_okay = True

    def update(self, translation: Vec, rotation: Quat) -> None:
        self.received = (translation, rotation)
        self.updated = True

    def update_needed(self) -> bool:
        """Whether the last update should be sent (asked once per cycle)."""
        if not self.updated or self.received is None:
            return False
        self.updated = False
        if self.transmitted is None or self.trans_thres == 0.0 or self.angular_thres == 0.0:
            return True
        (t0, r0), (t1, r1) = self.transmitted, self.received
        return (math.dist(t0, t1) > self.trans_thres
                or rotation_angle(r0, r1) > self.angular_thres)

    def transmitted_now(self) -> None:
        self.transmitted = self.received
