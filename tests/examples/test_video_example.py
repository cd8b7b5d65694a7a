"""Seed "Opencv-Ros": the webcam publisher and the imshow subscriber, run unmodified.

No webcam and no HighGUI here, so both run with tests/examples/fakecam on PYTHONPATH: its
sitecustomize.py makes ``cv2.VideoCapture(0)`` produce synthetic frames and ``cv2.imshow`` save
what it is given (see the module docstring there). The test then checks that the frames the
subscriber showed are the synthetic camera frames plus the publisher's blue 'A'.
"""

from __future__ import annotations

import sys
from pathlib import Path

import cv2
import numpy as np

from support import EXAMPLES, PYTHON, Proc, ros_env, wait_until

VIDEO = EXAMPLES / "video"
#: a test-only shim: a synthetic webcam and an imshow that writes PNGs
FAKECAM = Path(__file__).resolve().parent / "fakecam"
sys.path.insert(0, str(FAKECAM))
from fakecam_synthetic import HEIGHT, WIDTH, frame_index, synthetic_frame  # noqa: E402


def shown_count(out: Path) -> int:
    log = out / "calls.log"
    if not log.exists():
        return 0
    return sum(1 for line in log.read_text().splitlines() if line.startswith("imshow camera "))


def test_video_pub_sub_with_fake_camera(minros_core, ros_home, tmp_path):
    out = tmp_path / "fakecam"
    out.mkdir()
    env = ros_env(minros_core, ros_home, {"PYTHONPATH": str(FAKECAM), "FAKECAM_DIR": str(out)})
    sub = Proc([PYTHON, str(VIDEO / "video_sub.py")], env)
    pub = Proc([PYTHON, str(VIDEO / "video_pub.py")], env)
    sub_out = ""  # a read_until that fails must not be hidden by the finally below
    try:
        sub_out = sub.read_until("receiving video frame", timeout=20)
        wait_until(lambda: shown_count(out) >= 3, timeout=10, what="three frames shown")
    finally:
        pub_out = pub.stop()
        sub_out += sub.stop()
    assert "publishing video frame" in pub_out
    assert "Traceback" not in pub_out + sub_out
    calls = (out / "calls.log").read_text().splitlines()
    assert "VideoCapture 0" in calls  # the publisher opened "the default webcam"
    shows = [line for line in calls if line.startswith("imshow ")]
    assert all(line.split()[2] == f"{HEIGHT}x{WIDTH}x3" for line in shows), shows

    check_shown_frame(out / "camera.png")


def check_shown_frame(path: Path) -> None:
    """The frame imshow got is synthetic camera frame N plus the publisher's blue 'A' only."""
    shown = cv2.imread(str(path))
    assert shown is not None and shown.shape == (HEIGHT, WIDTH, 3)
    index = frame_index(shown)
    assert index >= 1
    original = synthetic_frame(index)
    changed = np.any(shown != original, axis=2)
    ys, xs = changed.nonzero()
    assert len(xs) > 50, "the publisher's 'A' is missing"
    # Everything that changed is the glyph drawn at org (150, 150): bottom-left corner, ~22 px high.
    assert xs.min() >= 145 and xs.max() <= 180 and ys.min() >= 120 and ys.max() <= 155
    blue = np.all(shown == (255, 0, 0), axis=2)  # BGR (255, 0, 0) as in cv2.putText's colour
    assert blue.sum() > 20 and not np.any(np.all(original == (255, 0, 0), axis=2))
