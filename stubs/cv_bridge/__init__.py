"""Stand-in for ROS's cv_bridge: convert between sensor_msgs/Image and OpenCV (numpy) images."""

from cv_bridge.core import CvBridge, CvBridgeError, getCvType

__all__ = ["CvBridge", "CvBridgeError", "getCvType"]
