"""image_geometry stand-in: PinholeCameraModel and StereoCameraModel (behaviour in
minros.image_geometry)."""

from __future__ import absolute_import  # noqa: F401, UP010 (ROS's module has the name)

from .cameramodels import PinholeCameraModel, StereoCameraModel  # noqa: F401
