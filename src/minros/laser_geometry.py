"""laser_geometry: project a sensor_msgs/LaserScan into a sensor_msgs/PointCloud2.

``LaserProjection().projectLaser(scan, range_cutoff=-1.0, channel_options=DEFAULT)`` gives the
cloud ROS's Python module gives, field for field and byte for byte: points x, y, z (float32)
for the ranges within [range_min, cutoff) (cutoff: range_max, or range_cutoff when smaller),
then the channels asked for: "intensity" (when the scan has intensities), "index" (int32),
"distances", "stamps" (i * time_increment) and "vp_x", "vp_y", "vp_z" (zeros). The angles'
cosines and sines are kept between scans of the same geometry, as there. ROS builds the points
one by one in Python; this computes them as numpy columns (the same float64 arithmetic, so the
same float32 values) and packs them in one step.
"""

from __future__ import annotations

from typing import Any, List, Tuple

import numpy as np

from minros.msgs import get_message_class

__all__ = ["LaserProjection"]

_FLOAT32, _INT32 = 7, 5  # sensor_msgs/PointField datatypes


class LaserProjection:
    """Projects laser scans into point clouds (see the module's text)."""

    LASER_SCAN_INVALID = -1.0
    LASER_SCAN_MIN_RANGE = -2.0
    LASER_SCAN_MAX_RANGE = -3.0

    class ChannelOption:
        """The channels projectLaser adds, or-ed together."""

        NONE = 0x00
        INTENSITY = 0x01
        INDEX = 0x02
        DISTANCE = 0x04
        TIMESTAMP = 0x08
        VIEWPOINT = 0x10
        DEFAULT = INTENSITY | INDEX

    def __init__(self) -> None:
        self.__angle_min = 0.0
        self.__angle_max = 0.0
        self.__cos_sin_map = np.array([[]])

    def projectLaser(self, scan_in: Any, range_cutoff: float = -1.0,  # noqa: N802 (ROS's name)
                     channel_options: int = ChannelOption.DEFAULT) -> Any:
        """The PointCloud2 of ``scan_in``, in the scan's frame and with its header."""
        ranges = np.asarray(scan_in.ranges, dtype=np.float64).reshape(-1)
        n = ranges.shape[0]
        if (self.__cos_sin_map.shape[1] != n or self.__angle_min != scan_in.angle_min
                or self.__angle_max != scan_in.angle_max):
            self.__angle_min = scan_in.angle_min
            self.__angle_max = scan_in.angle_max
            angles = scan_in.angle_min + np.arange(n) * scan_in.angle_increment
            self.__cos_sin_map = np.array([np.cos(angles), np.sin(angles)])
        output = ranges * self.__cos_sin_map
        if range_cutoff < 0:
            range_cutoff = scan_in.range_max
        else:
            range_cutoff = min(range_cutoff, scan_in.range_max)
        keep = (ranges < range_cutoff) & (ranges >= scan_in.range_min)
        index = np.nonzero(keep)[0]
        columns: List[Tuple[str, int, Any]] = [
            ("x", _FLOAT32, output[0, keep]), ("y", _FLOAT32, output[1, keep]),
            ("z", _FLOAT32, 0.0)]
        options = channel_options
        if options & self.ChannelOption.INTENSITY and len(scan_in.intensities) > 0:
            intensities = np.asarray(scan_in.intensities, dtype=np.float64).reshape(-1)
            if intensities.shape[0] < n and index.size and index[-1] >= intensities.shape[0]:
                raise IndexError(f"the scan has {n} ranges but only {intensities.shape[0]} "
                                 "intensities")
            columns.append(("intensity", _FLOAT32, intensities[index]))
        if options & self.ChannelOption.INDEX:
            columns.append(("index", _INT32, index))
        if options & self.ChannelOption.DISTANCE:
            columns.append(("distances", _FLOAT32, ranges[keep]))
        if options & self.ChannelOption.TIMESTAMP:
            columns.append(("stamps", _FLOAT32, index * scan_in.time_increment))
        if options & self.ChannelOption.VIEWPOINT:
            columns += [("vp_x", _FLOAT32, 0.0), ("vp_y", _FLOAT32, 0.0), ("vp_z", _FLOAT32, 0.0)]
        return _cloud(scan_in.header, columns, index.shape[0])


def _cloud(header: Any, columns: List[Tuple[str, int, Any]], count: int) -> Any:
    """A one-row PointCloud2 of 4-byte fields in ``columns``' order."""
    point_field = get_message_class("sensor_msgs/PointField")
    fields = [point_field(name, 4 * i, datatype, 1) for i, (name, datatype, _) in enumerate(columns)]
    dtype = np.dtype([(name, "<f4" if datatype == _FLOAT32 else "<i4")
                      for name, datatype, _ in columns])
    records = np.zeros(count, dtype=dtype)
    for name, _, values in columns:
        records[name] = values
    step = dtype.itemsize
    return get_message_class("sensor_msgs/PointCloud2")(
        header=header, height=1, width=count, is_dense=False, is_bigendian=False,
        fields=fields, point_step=step, row_step=step * count, data=records.tobytes())
