"""Draw minros sim's default world (src/minros/sim/share/worlds/rooms.{pgm,yaml}).

Three rooms in a 10 m x 8 m box at 5 cm per pixel, the map frame's origin in the middle, where
the robot starts facing +x with 2.3 m free ahead. Run it again after changing the shapes:
``python scripts/sim_world.py``.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

RESOLUTION = 0.05
ORIGIN = (-5.0, -4.0)
WIDTH, HEIGHT = 200, 160  # pixels: 10 m x 8 m
OUT = Path(__file__).resolve().parent.parent / "src" / "minros" / "sim" / "share" / "worlds"


def main() -> None:
    occupied = np.zeros((HEIGHT, WIDTH), dtype=bool)  # row 0 = bottom (y = -4)
    xs = ORIGIN[0] + (np.arange(WIDTH) + 0.5) * RESOLUTION
    ys = ORIGIN[1] + (np.arange(HEIGHT) + 0.5) * RESOLUTION
    x, y = np.meshgrid(xs, ys)

    def box(x0: float, y0: float, x1: float, y1: float) -> None:
        occupied[(x >= x0) & (x <= x1) & (y >= y0) & (y <= y1)] = True

    def disc(cx: float, cy: float, r: float) -> None:
        occupied[(x - cx) ** 2 + (y - cy) ** 2 <= r * r] = True

    box(-5.0, -4.0, 5.0, -3.9)   # outer walls
    box(-5.0, 3.9, 5.0, 4.0)
    box(-5.0, -4.0, -4.9, 4.0)
    box(4.9, -4.0, 5.0, 4.0)
    box(2.45, -4.0, 2.55, 1.0)   # the east room's wall, a 1 m door at y 1..2
    box(2.45, 2.0, 2.55, 4.0)
    box(-5.0, -1.55, -1.6, -1.45)  # the south-west room's wall, a door at x -1.6..-0.6
    box(-0.6, -1.55, 0.6, -1.45)
    disc(-2.5, 1.6, 0.4)          # a pillar
    box(0.6, 2.3, 1.4, 2.9)       # a table
    box(3.7, -2.4, 4.3, -1.8)     # a box in the east room
    disc(-3.6, -2.9, 0.3)         # a bin in the south-west room
    box(3.4, 2.6, 4.9, 2.75)      # a shelf in the east room

    pixels = np.where(occupied, 0, 254).astype(np.uint8)[::-1]  # the picture's top row first
    OUT.mkdir(parents=True, exist_ok=True)
    header = f"P5\n# minros sim default world, {RESOLUTION} m/pix\n{WIDTH} {HEIGHT}\n255\n"
    (OUT / "rooms.pgm").write_bytes(header.encode("ascii") + pixels.tobytes())
    (OUT / "rooms.yaml").write_text(
        "# minros sim's default world (map_server's format); drawn by scripts/sim_world.py\n"
        "image: rooms.pgm\n"
        f"resolution: {RESOLUTION}\n"
        f"origin: [{ORIGIN[0]}, {ORIGIN[1]}, 0.0]\n"
        "negate: 0\noccupied_thresh: 0.65\nfree_thresh: 0.196\n")


if __name__ == "__main__":
    main()
