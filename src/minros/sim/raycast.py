"""Laser rays against a grid of walls, all rays of all robots in one numpy batch.

The method is ray marching over a distance field (as in range_libc's "RM"): each free cell
knows the Euclidean distance from its centre to the nearest wall cell's centre
(``cv2.distanceTransform``), so a ray at distance ``d`` from the nearest wall may jump
``d - 1.5`` cells without passing through one (its own point lies within 0.71 cells of its
cell's centre, and every point of a wall cell within 0.71 of that cell's centre). Where that
jump is shorter than the way out of the current cell, the ray steps exactly to the next cell
boundary instead, as a grid traversal (Amanatides and Woo) does; so no wall cell is ever
skipped, and a ray enters a wall exactly at its boundary: the range is exact, not rounded to
cells. Open space costs a few big jumps; only rays running along a wall take small steps, and
rays that are done leave the batch.

Obstacles that are not cells (the other robots, discs) are intersected analytically by
:func:`cast_discs`.
"""

from __future__ import annotations

import math

import numpy as np
from numpy.typing import ArrayLike

from minros.sim.grid import GridMap

#: How far a jump stays from the nearest wall centre (cells): two half-diagonals, rounded up.
_SAFETY = 1.5
#: Past a cell boundary by this much (cells), so that floor() lands in the next cell.
_EPSILON = 1e-6


class RayCaster:
    """Casts rays against the wall cells of a grid (``walls[row, col]`` True = wall)."""

    def __init__(self, grid: GridMap, walls: np.ndarray) -> None:
        import cv2

        if walls.shape != grid.data.shape:
            raise ValueError("walls must have the grid's shape")
        self.grid = grid
        self.walls = np.ascontiguousarray(walls, dtype=bool)
        self.height, self.width = self.walls.shape
        if self.walls.any():
            free = (~self.walls).astype(np.uint8)
            dist = cv2.distanceTransform(free, cv2.DIST_L2, cv2.DIST_MASK_PRECISE)
        else:
            dist = np.full(self.walls.shape, np.inf, dtype=np.float32)
        dist[self.walls] = 0.0
        # flat, so one take() per step indexes it
        self._dist = np.ascontiguousarray(dist, dtype=np.float64).ravel()

    def cast(self, x: ArrayLike, y: ArrayLike, angles: ArrayLike, max_range: float, max_steps: int = 100000) -> np.ndarray:
        """Ranges (metres) of rays from (x[i], y[i]) at headings angles[i] (map frame),
        ``inf`` where no wall lies within ``max_range`` or the ray leaves the grid."""
        grid = self.grid
        angles = np.asarray(angles, dtype=float)
        n = angles.size
        result = np.full(n, np.inf)
        if n == 0:
            return result
        gx, gy = grid.to_cells(np.broadcast_to(np.asarray(x, dtype=float), (n,)),
                               np.broadcast_to(np.asarray(y, dtype=float), (n,)))
        heading = grid.yaw_to_grid(angles)
        dx, dy = np.cos(heading), np.sin(heading)
        # 1/d with inf for axis-parallel rays (never reaching the boundary on that axis)
        with np.errstate(divide="ignore"):
            inv_dx = np.where(dx != 0.0, 1.0 / np.where(dx != 0.0, dx, 1.0), np.inf)
            inv_dy = np.where(dy != 0.0, 1.0 / np.where(dy != 0.0, dy, 1.0), np.inf)
        t_max = max_range / grid.resolution
        t = np.zeros(n)
        index = np.arange(n)
        width, height = self.width, self.height
        ox, oy = np.asarray(gx, dtype=float).copy(), np.asarray(gy, dtype=float).copy()
        for _ in range(max_steps):
            px = ox + t * dx
            py = oy + t * dy
            col = np.floor(px)
            row = np.floor(py)
            alive = (col >= 0) & (col < width) & (row >= 0) & (row < height) & (t <= t_max)
            if not alive.all():
                keep = np.flatnonzero(alive)
                if keep.size == 0:
                    break
                ox, oy, dx, dy, inv_dx, inv_dy, t, index, px, py, col, row = (
                    a[keep] for a in (ox, oy, dx, dy, inv_dx, inv_dy, t, index, px, py, col, row))
            d = self._dist.take(row.astype(np.intp) * width + col.astype(np.intp))
            hit = d == 0.0
            if hit.any():
                result[index[hit]] = t[hit] * grid.resolution
                keep = np.flatnonzero(~hit)
                if keep.size == 0:
                    break
                ox, oy, dx, dy, inv_dx, inv_dy, t, index, px, py, col, row, d = (
                    a[keep] for a in (ox, oy, dx, dy, inv_dx, inv_dy, t, index, px, py, col,
                                      row, d))
            # the way out of the current cell along each axis (boundary at col or col + 1)
            with np.errstate(invalid="ignore"):  # 0 * inf on an axis-parallel ray
                exit_x = np.where(dx > 0, col + 1.0 - px, col - px) * inv_dx
                exit_y = np.where(dy > 0, row + 1.0 - py, row - py) * inv_dy
                exit_x = np.where(np.isnan(exit_x), np.inf, exit_x)
                exit_y = np.where(np.isnan(exit_y), np.inf, exit_y)
            t = t + np.maximum(d - _SAFETY, np.minimum(exit_x, exit_y) + _EPSILON)
        return result


def cast_discs(x: ArrayLike, y: ArrayLike, angles: ArrayLike, centres: np.ndarray, radii: np.ndarray,
               skip: np.ndarray | None = None) -> np.ndarray:
    """Distance along each ray (x[i], y[i], angles[i]) to the nearest of the discs
    ``centres[k]`` with ``radii[k]`` (``inf`` if none); ``skip[i]`` names a disc ray i ignores
    (its own robot), -1 for none. A ray starting inside a disc does not see it."""
    angles = np.asarray(angles, dtype=float)
    n = angles.size
    if n == 0 or len(centres) == 0:
        return np.full(n, np.inf)
    ox = np.broadcast_to(np.asarray(x, dtype=float), (n,))[:, None]
    oy = np.broadcast_to(np.asarray(y, dtype=float), (n,))[:, None]
    cx, cy = centres[None, :, 0], centres[None, :, 1]
    dx, dy = np.cos(angles)[:, None], np.sin(angles)[:, None]
    rel_x, rel_y = ox - cx, oy - cy
    b = dx * rel_x + dy * rel_y
    c = rel_x * rel_x + rel_y * rel_y - radii[None, :] ** 2
    disc = b * b - c
    with np.errstate(invalid="ignore"):
        t = -b - np.sqrt(disc)
    valid = (disc >= 0) & (c > 0) & (t >= 0)
    if skip is not None:
        valid &= np.arange(len(centres))[None, :] != np.asarray(skip)[:, None]
    t = np.where(valid, t, np.inf)
    return t.min(axis=1)


def scan_angles(count: int = 360, angle_min: float = 0.0,
                increment: float | None = None) -> np.ndarray:
    """The beam angles of a scan (TurtleBot3's LDS: 360 beams from 0, one degree apart)."""
    step = 2.0 * math.pi / count if increment is None else increment
    return angle_min + step * np.arange(count)
