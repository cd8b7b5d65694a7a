"""The joint table of joint_state_publisher: defaults, sources, mimics, one message's lists."""

from __future__ import annotations

import math
from typing import Any, Dict, List, Optional, Tuple

from minros.urdf_model import URDFError, parse_joints

__all__ = ["JointTable"]


class JointTable:
    """Free joints (with limits and current values) and dependent (mimic) joints, in URDF
    order."""

    def __init__(self, description: str, zeros: Optional[Dict[str, float]] = None,
                 dependent_joints: Optional[Dict[str, Dict[str, Any]]] = None,
                 use_mimic: bool = True, use_small: bool = True,
                 default_positions: bool = True, default_velocities: bool = False,
                 default_efforts: bool = False) -> None:
        zeros = zeros or {}
        self.dependent: Dict[str, Dict[str, Any]] = dict(dependent_joints or {})
        self.free: Dict[str, Dict[str, Any]] = {}
        self.order: List[str] = []
        self.warnings: List[str] = []
        for joint in parse_joints(description, robot_anywhere=True):
            if not joint.moving:
                continue
            self.order.append(joint.name)
            if joint.type == "continuous":
                low, high = -math.pi, math.pi
            elif joint.lower is None or joint.upper is None:
                self.warnings.append(f"{joint.name} is not fixed, nor continuous, but limits "
                                     "are not specified!")
                continue
            else:
                low, high = joint.lower, joint.upper
            if use_small:
                if joint.soft_lower is not None:
                    low = max(low, joint.soft_lower)
                if joint.soft_upper is not None:
                    high = min(high, joint.soft_upper)
            if use_mimic and joint.mimic is not None:
                entry: Dict[str, Any] = {"parent": joint.mimic.joint,
                                         "factor": joint.mimic.multiplier,
                                         "offset": joint.mimic.offset}
                self.dependent[joint.name] = entry
                continue
            if joint.name in self.dependent:
                continue
            zero = zeros.get(joint.name)
            if not zero:
                zero = (low + high) / 2 if low > 0 or high < 0 else 0.0
            values: Dict[str, Any] = {"min": low, "max": high, "zero": zero}
            if default_positions:
                values["position"] = zero
            if default_velocities:
                values["velocity"] = 0.0
            if default_efforts:
                values["effort"] = 0.0
            if joint.type == "continuous":
                values["continuous"] = True  # the key only where true, as ROS's table has it
            self.free[joint.name] = values
        for name in self.dependent:
            self._resolve(name)  # reject cycles and unknown joints now, with their names

    def _resolve(self, name: str) -> Tuple[str, float, float]:
        """(free joint, factor, offset) a dependent joint follows."""
        entry = self.dependent[name]
        parent, factor, offset = entry["parent"], entry.get("factor", 1.0), entry.get("offset", 0.0)
        chain = [name]
        while parent in self.dependent:
            if parent in chain:
                raise URDFError(f"Found an infinite recursive mimic chain: [{', '.join(chain)}, "
                                f"{parent}]")
            chain.append(parent)
            entry = self.dependent[parent]
            parent = entry["parent"]
            offset += factor * entry.get("offset", 0.0)
            factor *= entry.get("factor", 1.0)
        if parent not in self.free:
            raise URDFError(f"joint {name} mimics {parent}, which is not a free joint")
        return parent, factor, offset

    def update_from(self, names: List[str], positions: List[float], velocities: List[float],
                    efforts: List[float]) -> None:
        """Take the values a source topic's JointState gives for our free joints."""
        for i, name in enumerate(names):
            joint = self.free.get(name)
            if joint is None:
                continue
            if positions and i < len(positions):
                joint["position"] = positions[i]
            if velocities and i < len(velocities):
                joint["velocity"] = velocities[i]
            if efforts and i < len(efforts):
                joint["effort"] = efforts[i]

    def sweep(self, delta: float) -> None:
        """Move every free joint by ``delta``, bouncing at its limits (``~delta``)."""
        for joint in self.free.values():
            if "position" not in joint:
                continue
            forward = joint.get("forward", True)
            joint["position"] += delta if forward else -delta
            if joint["position"] > joint["max"]:
                if joint.get("continuous", False):
                    joint["position"] = joint["min"]
                else:
                    joint["position"] = joint["max"]
                    joint["forward"] = False
            elif joint["position"] < joint["min"]:
                joint["position"] = joint["min"]
                joint["forward"] = True

    def message_lists(self) -> Tuple[List[str], List[float], List[float], List[float]]:
        """(names, positions, velocities, efforts) of one JointState."""
        has_position = bool(self.dependent) or any("position" in j for j in self.free.values())
        has_velocity = any("velocity" in j for j in self.free.values())
        has_effort = any("effort" in j for j in self.free.values())
        names: List[str] = []
        positions: List[float] = []
        velocities: List[float] = []
        efforts: List[float] = []
        for name in self.order:
            if name in self.free:
                joint, factor, offset = self.free[name], 1.0, 0.0
            elif name in self.dependent:
                parent, factor, offset = self._resolve(name)
                joint = self.free[parent]
            else:
                continue  # a joint without limits: left out, as ROS's leaves it at 0
            names.append(name)
            if has_position:
                positions.append(joint["position"] * factor + offset if "position" in joint
                                 else 0.0)
            if has_velocity:
                velocities.append(joint["velocity"] * factor if "velocity" in joint else 0.0)
            if has_effort:
                efforts.append(joint.get("effort", 0.0))
        return names, positions, velocities, efforts
