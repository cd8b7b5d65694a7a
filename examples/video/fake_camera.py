#!/usr/bin/env python3
"""The webcam publisher (video_pub.py, unchanged) for machines without a camera.

    python examples/video/fake_camera.py [--size 640x480]

Replaces ``cv2.VideoCapture`` with a synthetic camera (a moving colour gradient with a frame
counter) and then runs video_pub.py exactly as ``python video_pub.py`` would; video_sub.py
shows the frames as it shows a real camera's.
"""

import argparse
import os
import runpy
import sys

import cv2
import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))


class FakeCamera:
    """What video_pub.py uses of cv2.VideoCapture: read() gives (True, a BGR frame)."""

    def __init__(self, source=0, width: int = 640, height: int = 480) -> None:
        self.source = source
        self.width, self.height = width, height
        self.count = 0
        ys, xs = np.mgrid[0:height, 0:width]
        self.xs, self.ys = xs.astype(np.int32), ys.astype(np.int32)

    def isOpened(self) -> bool:
        return True

    def read(self, image=None):
        self.count += 1
        shift = self.count * 4
        frame = np.empty((self.height, self.width, 3), dtype=np.uint8)
        frame[:, :, 0] = (self.xs + shift) % 256  # blue: a gradient sliding to the left
        frame[:, :, 1] = (self.ys * 255) // max(1, self.height - 1)
        frame[:, :, 2] = 128
        cv2.putText(frame, f"fake camera {self.count}", (20, self.height - 20),
                    cv2.FONT_HERSHEY_SIMPLEX, 1, (255, 255, 255), 2, cv2.LINE_AA)
        return True, frame

    def release(self) -> None:
        pass


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--size", default="640x480", help="frame size WIDTHxHEIGHT")
    args, rest = parser.parse_known_args()
    width, height = (int(n) for n in args.size.lower().split("x"))
    cv2.VideoCapture = lambda source=0, *more: FakeCamera(source, width, height)
    sys.argv = [os.path.join(HERE, "video_pub.py"), *rest]
    runpy.run_path(sys.argv[0], run_name="__main__")


if __name__ == "__main__":
    main()
