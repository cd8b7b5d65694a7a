"""laser_geometry stand-in: LaserProjection (behaviour in minros.laser_geometry)."""

from .laser_geometry import LaserProjection  # noqa: F401
