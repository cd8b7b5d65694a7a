"""camera_calibration_parsers stand-in: read a camera calibration file, YAML or INI
(minros.camera_info_manager)."""

from minros.camera_info_manager import readCalibration  # noqa: F401
from sensor_msgs.msg import CameraInfo  # noqa: F401
