"""rosbag's progress bar: ``path  42%  1.2 GB / 2.9 GB 00:12 ETA``, redrawn once a second."""

from __future__ import annotations

import os
import shutil
import sys
import time
from typing import TextIO

from minros.bag.info import human_size


class ProgressMeter:
    def __init__(self, path: str, bytes_total: int, refresh_rate: float = 1.0,
                 out: TextIO | None = None) -> None:
        self.path = path
        self.bytes_total = bytes_total
        self.refresh_rate = refresh_rate
        self.out = out or sys.stdout
        self.start_time = time.time()
        self.elapsed = 0.0
        self.update_elapsed = 0.0
        self.bytes_read = 0
        self._update()

    def step(self, bytes_read: int, force_update: bool = False) -> None:
        self.bytes_read = bytes_read
        self.elapsed = time.time() - self.start_time
        if force_update or self.elapsed - self.update_elapsed > self.refresh_rate:
            self._update()
            self.update_elapsed = self.elapsed

    def _update(self) -> None:
        width = max(terminal_width(self.out) - 37, 10)
        path = self.path if len(self.path) <= width else "..." + self.path[-width + 3:]
        total = human_size(float(self.bytes_total))
        if self.bytes_read < self.bytes_total:
            fraction = self.bytes_read / self.bytes_total
            if fraction > 0.0:
                eta = self.elapsed * (1.0 / fraction - 1.0)
                eta_str = "--:--" if eta / 60 > 99 else f"{int(eta / 60):02d}:{int(eta % 60):02d}"
            else:
                eta_str = "--:--"
            line = f"{path:<{width}} {int(100.0 * fraction):3d}% {human_size(float(self.bytes_read)):>8} / {total:>8} {eta_str} ETA"
        else:
            line = f"{path:<{width}} 100% {total:>19} {int(self.elapsed / 60):02d}:{int(self.elapsed % 60):02d}    "
        self.out.write("\r " + line)
        self.out.flush()

    def finish(self) -> None:
        self.step(self.bytes_total, force_update=True)
        self.out.write("\n")
        self.out.flush()


def terminal_width(out: TextIO) -> int:
    try:
        width = os.get_terminal_size(out.fileno()).columns
    except (OSError, ValueError, AttributeError):
        width = 0
    if width <= 0:
        width = shutil.get_terminal_size((80, 24)).columns
    return width or 80
