"""Test-only stand-ins for a webcam and an OpenCV window (tests/examples/test_video_example.py).

Why this exists: the seed's "Opencv-Ros" example reads ``cv2.VideoCapture(0)`` (there is no
webcam on test machines) and shows frames with ``cv2.imshow`` (opencv-python-headless, which minros
depends on, has no HighGUI: imshow raises). The example scripts must run unmodified, so this module,
found by Python's ``site`` machinery because the test puts this directory on PYTHONPATH of the
two subprocesses only, patches cv2 when FAKECAM_DIR is set:

* ``cv2.VideoCapture(...)`` yields synthetic 640x480 BGR frames (see fakecam_synthetic.py);
* ``cv2.imshow(win, img)`` writes ``FAKECAM_DIR/<win>.png`` (atomically) and appends a line
  ``imshow <win> <h>x<w>x<c> <count>`` to ``FAKECAM_DIR/calls.log``;
* ``cv2.waitKey`` returns -1 (no key) and ``cv2.destroyAllWindows`` is recorded.
"""

from __future__ import annotations

import os

_OUT = os.environ.get("FAKECAM_DIR")

if _OUT:
    import threading

    import cv2
    from fakecam_synthetic import HEIGHT, WIDTH, synthetic_frame

    _lock = threading.Lock()
    _shown = [0]

    def _record(line: str) -> None:
        with _lock, open(os.path.join(_OUT, "calls.log"), "a") as log:
            log.write(line + "\n")

    class FakeVideoCapture:
        """Enough of cv2.VideoCapture for ``cap.read()`` loops."""

        def __init__(self, source=0, *args, **kwargs) -> None:
            self.source = source
            self.count = 0
            self.opened = True
            _record(f"VideoCapture {source!r}")

        def isOpened(self) -> bool:
            return self.opened

        def read(self, image=None):
            if not self.opened:
                return False, None
            self.count += 1
            return True, synthetic_frame(self.count)

        def get(self, prop_id: int) -> float:
            return {cv2.CAP_PROP_FRAME_WIDTH: float(WIDTH),
                    cv2.CAP_PROP_FRAME_HEIGHT: float(HEIGHT)}.get(prop_id, 0.0)

        def release(self) -> None:
            self.opened = False

    def imshow(winname: str, mat) -> None:
        with _lock:
            _shown[0] += 1
            count = _shown[0]
        path = os.path.join(_OUT, f"{winname}.png")
        tmp = os.path.join(_OUT, f".{winname}.tmp.png")
        cv2.imwrite(tmp, mat)
        os.replace(tmp, path)
        shape = "x".join(str(n) for n in mat.shape)
        _record(f"imshow {winname} {shape} {count}")

    def waitKey(delay: int = 0) -> int:
        return -1

    def destroyAllWindows() -> None:
        _record("destroyAllWindows")

    cv2.VideoCapture = FakeVideoCapture
    cv2.imshow = imshow
    cv2.waitKey = waitKey
    cv2.destroyAllWindows = destroyAllWindows
