"""Synthetic "webcam" frames for the video example test (see sitecustomize.py next to this file)."""

from __future__ import annotations

import numpy as np

WIDTH, HEIGHT = 640, 480


def synthetic_frame(index: int) -> np.ndarray:
    """Frame ``index``: a BGR colour gradient with the index stamped in the first 4 pixels.

    The gradient has no pure blue (255, 0, 0) anywhere, so the publisher's blue 'A' is easy to
    tell apart; the stamp lets a test regenerate exactly the frame a picture came from.
    """
    ys, xs = np.mgrid[0:HEIGHT, 0:WIDTH]
    frame = np.empty((HEIGHT, WIDTH, 3), dtype=np.uint8)
    frame[:, :, 0] = 40 + (xs * 100 // WIDTH)  # blue 40..139
    frame[:, :, 1] = 60 + (ys * 120 // HEIGHT)  # green 60..179
    frame[:, :, 2] = 200 - (xs * 80 // WIDTH)  # red 121..200
    stamp = int(index).to_bytes(4, "big")
    for i, byte in enumerate(stamp):
        frame[0, i] = (byte, byte, byte)
    return frame


def frame_index(frame: np.ndarray) -> int:
    """The index stamped by :func:`synthetic_frame`."""
    return int.from_bytes(bytes(int(frame[0, i, 0]) for i in range(4)), "big")
