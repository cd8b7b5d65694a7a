"""Stand-in for ROS's cv_bridge: convert between sensor_msgs/Image and OpenCV (numpy) images
(the behaviour lives in ``minros.cv_bridge``)."""

from minros.cv_bridge import CvBridge, CvBridgeError, cvtColorForDisplay, getCvType

__all__ = ["CvBridge", "CvBridgeError", "cvtColorForDisplay", "getCvType"]
