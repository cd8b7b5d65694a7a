"""An occupancy grid placed in the world, as ``nav_msgs/OccupancyGrid`` places it.

``data[row, col]`` holds the cell's occupancy (0 free ... 100 occupied, -1 unknown); row 0 is
the bottom row of the picture (OccupancyGrid's order: index ``row * width + col``). The origin
``(x, y, yaw)`` is the pose of the lower-left corner of cell (0, 0) in the map frame;
map_server allows a yaw, so every conversion here rotates by it (most maps have yaw 0).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Tuple

import numpy as np
from numpy.typing import ArrayLike

#: Occupancy at or above which the simulator treats a cell as a wall: map_saver's default
#: ``--occ`` threshold, i.e. the cells map_saver would write black.
WALL_THRESHOLD = 65


@dataclass
class GridMap:
    """Occupancy values on a grid with a resolution (m/cell) and an origin pose."""

    data: np.ndarray  # int8, shape (height, width)
    resolution: float
    origin: Tuple[float, float, float] = (0.0, 0.0, 0.0)

    def __post_init__(self) -> None:
        self.data = np.ascontiguousarray(self.data, dtype=np.int8)
        if self.data.ndim != 2:
            raise ValueError("an occupancy grid is two-dimensional")
        if not (math.isfinite(self.resolution) and self.resolution > 0):
            raise ValueError(f"resolution must be a positive number of metres, not {self.resolution}")
        ox, oy, oyaw = (float(v) for v in self.origin)
        self.origin = (ox, oy, oyaw)
        self._cos, self._sin = math.cos(oyaw), math.sin(oyaw)

    @property
    def width(self) -> int:
        return int(self.data.shape[1])

    @property
    def height(self) -> int:
        return int(self.data.shape[0])

    def walls(self, threshold: int = WALL_THRESHOLD) -> np.ndarray:
        """Boolean mask of the cells at or above ``threshold`` (unknown cells are not walls)."""
        return self.data >= threshold

    # -- coordinates: "cell units" are metres / resolution from the origin, along the grid axes

    def to_cells(self, x: ArrayLike, y: ArrayLike) -> Tuple[np.ndarray, np.ndarray]:
        """World (map frame) metres -> continuous cell coordinates (col, row); arrays allowed."""
        dx = np.asarray(x, dtype=float) - self.origin[0]
        dy = np.asarray(y, dtype=float) - self.origin[1]
        gx = (self._cos * dx + self._sin * dy) / self.resolution
        gy = (-self._sin * dx + self._cos * dy) / self.resolution
        return gx, gy

    def to_world(self, gx: ArrayLike, gy: ArrayLike) -> Tuple[np.ndarray, np.ndarray]:
        """Continuous cell coordinates -> world metres (a cell's centre is ``col + 0.5``)."""
        lx = np.asarray(gx, dtype=float) * self.resolution
        ly = np.asarray(gy, dtype=float) * self.resolution
        return (self.origin[0] + self._cos * lx - self._sin * ly,
                self.origin[1] + self._sin * lx + self._cos * ly)

    def yaw_to_grid(self, yaw: ArrayLike) -> np.ndarray:
        """A heading in the map frame -> the same heading measured on the grid's axes."""
        return np.asarray(yaw, dtype=float) - self.origin[2]

    def cell_of(self, x: float, y: float) -> Tuple[int, int] | None:
        """(row, col) of the cell holding world point (x, y), or None outside the grid."""
        gx, gy = self.to_cells(x, y)
        col, row = math.floor(float(gx)), math.floor(float(gy))
        if 0 <= col < self.width and 0 <= row < self.height:
            return row, col
        return None

    def bounds(self) -> Tuple[float, float, float, float]:
        """(min_x, min_y, max_x, max_y) of the grid's corners in the world."""
        xs, ys = self.to_world(np.array([0, self.width, 0, self.width]),
                               np.array([0, 0, self.height, self.height]))
        return float(xs.min()), float(ys.min()), float(xs.max()), float(ys.max())
