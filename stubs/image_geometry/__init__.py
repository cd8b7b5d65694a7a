"""image_geometry stand-in: PinholeCameraModel and StereoCameraModel (behaviour in
minros.image_geometry)."""

from .cameramodels import PinholeCameraModel, StereoCameraModel  # noqa: F401
