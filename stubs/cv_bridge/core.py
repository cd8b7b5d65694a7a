"""cv_bridge.core, as scripts import it (``from cv_bridge.core import CvBridge``)."""

from minros.cv_bridge import CvBridge, CvBridgeError, getCvType

__all__ = ["CvBridge", "CvBridgeError", "getCvType"]
