"""camera_calibration_parsers_wrapper stand-in: ROS's C++ reader as readCalibration calls it,
``(ok, camera name, serialized CameraInfo)``."""

from __future__ import annotations

import io
from typing import Tuple

from minros.camera_info_manager import readCalibration


def __readCalibrationWrapper(file_name: str) -> Tuple[bool, str, bytes]:  # noqa: N802
    found = readCalibration(file_name)
    if found is None:
        return False, "", b""
    name, info = found
    buff = io.BytesIO()
    info.serialize(buff)
    return True, name, buff.getvalue()
