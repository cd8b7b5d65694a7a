"""camera_info_manager stand-in (ROS 1's camera_info_manager_py; see minros.camera_info_manager)."""

from minros.camera_info_manager import *  # noqa: F401,F403
from minros.camera_info_manager import __all__ as __all__  # noqa: PLC0414
