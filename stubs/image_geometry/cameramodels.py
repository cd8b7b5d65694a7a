"""image_geometry.cameramodels stand-in (see minros.image_geometry)."""

import copy  # noqa: F401
import math  # noqa: F401

import cv2  # noqa: F401
import numpy  # noqa: F401

from minros.image_geometry import PinholeCameraModel, StereoCameraModel, mkmat  # noqa: F401
