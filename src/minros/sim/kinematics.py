"""Differential drive: a velocity command -> the pose a step later, and the wheels' angles.

The robot follows an arc at constant linear speed ``v`` (m/s) and turn rate ``w`` (rad/s)
for ``dt`` seconds; integrating the arc exactly (not by Euler steps) keeps a robot told to
drive a circle on that circle at any step size. Limits are the TurtleBot3 Burger's (its
firmware clamps commands to them; so does this simulator, unless told otherwise).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Tuple

#: TurtleBot3 Burger (turtlebot3_teleop's BURGER_MAX_LIN_VEL / BURGER_MAX_ANG_VEL)
MAX_LINEAR = 0.22
MAX_ANGULAR = 2.84
#: TurtleBot3 Burger wheels (turtlebot3_burger.gazebo.xacro: separation 0.160, diameter 0.066)
WHEEL_SEPARATION = 0.160
WHEEL_RADIUS = 0.033


def wrap_angle(angle: float) -> float:
    """``angle`` in [-pi, pi)."""
    return (angle + math.pi) % (2.0 * math.pi) - math.pi


@dataclass(frozen=True)
class Limits:
    """Speed limits (absolute values); ``inf`` disables one."""

    linear: float = MAX_LINEAR
    angular: float = MAX_ANGULAR

    def clamp(self, v: float, w: float) -> Tuple[float, float]:
        return (max(-self.linear, min(self.linear, v)), max(-self.angular, min(self.angular, w)))


def integrate(x: float, y: float, yaw: float, v: float, w: float,
              dt: float) -> Tuple[float, float, float]:
    """The pose after following the arc (v, w) for dt seconds from (x, y, yaw)."""
    if abs(w) < 1e-9:
        return x + v * dt * math.cos(yaw), y + v * dt * math.sin(yaw), yaw
    new_yaw = yaw + w * dt
    radius = v / w
    return (x + radius * (math.sin(new_yaw) - math.sin(yaw)),
            y - radius * (math.cos(new_yaw) - math.cos(yaw)),
            wrap_angle(new_yaw))


def wheel_speeds(v: float, w: float, separation: float = WHEEL_SEPARATION,
                 radius: float = WHEEL_RADIUS) -> Tuple[float, float]:
    """(left, right) wheel angular speeds in rad/s for body speeds (v, w)."""
    return ((v - w * separation / 2.0) / radius, (v + w * separation / 2.0) / radius)
