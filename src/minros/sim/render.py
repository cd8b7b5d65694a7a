"""The top-down picture of a world, as turtlesim draws its window: map, robots, laser hits.

The map is drawn in map_saver's grays (free 254, unknown 205, walls dark), scaled up by a whole
number of pixels per cell so that small maps are not tiny; each robot is a coloured disc with
a line showing its heading, and its laser's hits are dots of the same colour. The picture is
BGR (OpenCV's order, ``bgr8`` as a ``sensor_msgs/Image``).
"""

from __future__ import annotations

import math
from typing import Dict, Sequence, Tuple

import numpy as np
from numpy.typing import ArrayLike

from minros.sim.world import World

#: BGR colours, one per robot in turn
COLOURS: Sequence[Tuple[int, int, int]] = (
    (40, 110, 230), (200, 120, 30), (60, 170, 60), (160, 60, 160), (30, 160, 200),
    (120, 120, 40))
_SUBPIXEL = 4  # cv2 drawing with 4 fractional bits


def scale_for(grid_width: int, grid_height: int, target: int = 600, most: int = 8) -> int:
    """Pixels per cell: the largest whole number keeping the picture near ``target`` pixels."""
    return max(1, min(most, target // max(grid_width, grid_height, 1)))


class Renderer:
    """Draws a :class:`World`; the map background is drawn once."""

    def __init__(self, world: World, scale: int | None = None) -> None:
        import cv2

        self.world = world
        grid = world.grid
        self.scale = scale or scale_for(grid.width, grid.height)
        gray = np.full(grid.data.shape, 254, dtype=np.uint8)
        gray[grid.data == -1] = 205
        gray[world.walls] = 40
        gray = gray[::-1]  # row 0 of the grid is the bottom of the picture
        big = cv2.resize(gray, (grid.width * self.scale, grid.height * self.scale),
                         interpolation=cv2.INTER_NEAREST)
        self.background = cv2.cvtColor(big, cv2.COLOR_GRAY2BGR)

    def pixel(self, x: ArrayLike, y: ArrayLike) -> Tuple[np.ndarray, np.ndarray]:
        """World metres -> picture pixel coordinates (floats; arrays allowed)."""
        gx, gy = self.world.grid.to_cells(x, y)
        return gx * self.scale, (self.world.grid.height - gy) * self.scale

    def render(self, scans: Dict[str, np.ndarray] | None = None) -> np.ndarray:
        import cv2

        image = self.background.copy()
        f = 1 << _SUBPIXEL
        for i, robot in enumerate(self.world.robots.values()):
            colour = COLOURS[i % len(COLOURS)]
            ranges = (scans or {}).get(robot.name)
            if ranges is not None:
                lx, ly, lyaw = robot.laser_pose()
                angles = robot.laser.angles() + lyaw
                ok = np.isfinite(ranges)
                hx = lx + ranges[ok] * np.cos(angles[ok])
                hy = ly + ranges[ok] * np.sin(angles[ok])
                px, py = self.pixel(hx, hy)
                px, py = np.round(px).astype(int), np.round(py).astype(int)
                inside = (px >= 0) & (px < image.shape[1]) & (py >= 0) & (py < image.shape[0])
                for dx in (0, 1):
                    for dy in (0, 1):
                        image[np.clip(py[inside] + dy, 0, image.shape[0] - 1),
                              np.clip(px[inside] + dx, 0, image.shape[1] - 1)] = colour
            cx, cy = self.pixel(robot.x, robot.y)
            radius = robot.radius / self.world.grid.resolution * self.scale
            heading = self.world.grid.yaw_to_grid(robot.yaw)
            centre = (int(round(float(cx) * f)), int(round(float(cy) * f)))
            cv2.circle(image, centre, int(round(radius * f)), colour, -1, cv2.LINE_AA, _SUBPIXEL)
            cv2.circle(image, centre, int(round(radius * f)), (20, 20, 20), 1, cv2.LINE_AA, _SUBPIXEL)
            tip = (int(round((float(cx) + radius * math.cos(heading)) * f)),
                   int(round((float(cy) - radius * math.sin(heading)) * f)))
            cv2.line(image, centre, tip, (255, 255, 255), max(1, self.scale // 2), cv2.LINE_AA,
                     _SUBPIXEL)
            if robot.name:
                cv2.putText(image, robot.name, (int(cx + radius + 2), int(cy - radius)),
                            cv2.FONT_HERSHEY_SIMPLEX, 0.4, (20, 20, 20), 1, cv2.LINE_AA)
        return image
