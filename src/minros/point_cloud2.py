"""sensor_msgs.point_cloud2: reading and making ``sensor_msgs/PointCloud2`` messages.

The same functions and results as ROS's module (``read_points`` yields one tuple of Python
numbers per point, ``read_points_list`` namedtuples, ``create_cloud`` packs points after the
fields sorted by offset), computed with numpy: the cloud's bytes are viewed as a structured
array (one record per point, rows of ``row_step`` bytes) and turned into tuples in C, instead of
one ``struct.unpack_from`` per point. A cloud whose layout numpy cannot view (a field past
``point_step``, truncated data) falls back to ROS's per-point reading, so errors are the same.
"""

from __future__ import annotations

import math
import struct
import sys
from collections import namedtuple
from typing import Any, Iterable, Iterator, List, Sequence, Tuple

#: PointField datatype -> (struct code, size), as ROS's module
_DATATYPES = {1: ("b", 1), 2: ("B", 1), 3: ("h", 2), 4: ("H", 2), 5: ("i", 4), 6: ("I", 4),
              7: ("f", 4), 8: ("d", 8)}
_NUMPY = {"b": "i1", "B": "u1", "h": "i2", "H": "u2", "i": "i4", "I": "u4", "f": "f4", "d": "f8"}
#: points converted to tuples per step (keeps the generator's memory bounded)
_CHUNK = 65536

__all__ = ["read_points", "read_points_list", "create_cloud", "create_cloud_xyz32"]


def _layout(is_bigendian: bool, fields: Iterable[Any], field_names: Any = None
            ) -> Tuple[str, List[Tuple[str, int]]]:
    """ROS's struct format for the selected fields, and each value's (code, byte offset).

    Fields are taken in offset order; a gap before a field is padding; a field whose offset
    lies before the end of the previous one is read right after it (as the struct format
    reads it); an unknown datatype is reported and skipped."""
    fmt = ">" if is_bigendian else "<"
    offset = 0
    items: List[Tuple[str, int]] = []
    for field in sorted(fields, key=lambda f: f.offset):
        if field_names is not None and field.name not in field_names:
            continue
        if offset < field.offset:
            fmt += "x" * (field.offset - offset)
            offset = field.offset
        if field.datatype not in _DATATYPES:
            print(f"Skipping unknown PointField datatype [{field.datatype}]", file=sys.stderr)
            continue
        code, size = _DATATYPES[field.datatype]
        for _ in range(field.count):
            items.append((code, offset))
            offset += size
        fmt += field.count * code
    return fmt, items


def _dtype(is_bigendian: bool, items: Sequence[Tuple[str, int]], itemsize: int) -> Any:
    import numpy

    order = ">" if is_bigendian else "<"
    return numpy.dtype({"names": [f"f{i}" for i in range(len(items))],
                        "formats": [order + _NUMPY[code] for code, _ in items],
                        "offsets": [offset for _, offset in items], "itemsize": itemsize})


def _check_cloud(cloud: Any) -> None:
    assert getattr(cloud, "_type", None) == "sensor_msgs/PointCloud2", \
        "cloud is not a sensor_msgs.msg.PointCloud2"


def _records(cloud: Any, items: Sequence[Tuple[str, int]], size: int) -> Any:
    """The points as a structured array (height * width records), or None when the layout
    cannot be viewed that way."""
    import numpy

    width, height = cloud.width, cloud.height
    point_step, row_step = cloud.point_step, cloud.row_step
    if not items or size > point_step or width * point_step > row_step or height == 0 or width == 0:
        return None
    data = cloud.data
    buffer = numpy.frombuffer(data if not isinstance(data, list) else bytes(data), dtype=numpy.uint8)
    if buffer.size < row_step * (height - 1) + width * point_step:
        return None
    if buffer.size < row_step * height:  # a short last row: pad the view, never read past it
        buffer = numpy.concatenate([buffer, numpy.zeros(row_step * height - buffer.size, numpy.uint8)])
    rows = buffer[:row_step * height].reshape(height, row_step)[:, :width * point_step]
    return numpy.ascontiguousarray(rows).view(_dtype(cloud.is_bigendian, items, point_step)).reshape(-1)


def _nan_mask(records: Any, items: Sequence[Tuple[str, int]]) -> Any:
    import numpy

    mask = numpy.zeros(records.shape[0], dtype=bool)
    for i, (code, _) in enumerate(items):
        if code in "fd":
            mask |= numpy.isnan(records[f"f{i}"])
    return mask


def read_points(cloud: Any, field_names: Any = None, skip_nans: bool = False,
                uvs: Iterable[Tuple[int, int]] = ()) -> Iterator[tuple]:
    """One tuple of the selected fields' values per point (all fields by default), row by
    row; ``skip_nans`` drops points with a NaN, ``uvs`` reads only those (u, v) points."""
    _check_cloud(cloud)
    fmt, items = _layout(cloud.is_bigendian, cloud.fields, field_names)
    uvs = list(uvs)
    records = None if uvs else _records(cloud, items, struct.calcsize(fmt))
    if records is None:
        yield from _read_points_struct(cloud, fmt, skip_nans, uvs)
        return
    if skip_nans:
        records = records[~_nan_mask(records, items)]
    for start in range(0, records.shape[0], _CHUNK):
        yield from records[start:start + _CHUNK].tolist()


def _read_points_struct(cloud: Any, fmt: str, skip_nans: bool, uvs: List[Tuple[int, int]]
                        ) -> Iterator[tuple]:
    """ROS's reading, one point at a time (offsets and errors exactly as struct gives them)."""
    unpack_from = struct.Struct(fmt).unpack_from
    data, point_step, row_step = cloud.data, cloud.point_step, cloud.row_step
    if uvs:
        offsets: Iterable[int] = (row_step * v + point_step * u for u, v in uvs)
    else:
        offsets = (row_step * v + point_step * u for v in range(cloud.height)
                   for u in range(cloud.width))
    for offset in offsets:
        point = unpack_from(data, offset)
        if skip_nans and any(isinstance(x, float) and math.isnan(x) for x in point):
            continue
        yield point


def read_points_list(cloud: Any, field_names: Any = None, skip_nans: bool = False,
                     uvs: Iterable[Tuple[int, int]] = ()) -> List[Any]:
    """:func:`read_points` as a list of namedtuples ``Point(x=..., y=..., ...)``."""
    _check_cloud(cloud)
    if field_names is None:
        field_names = [f.name for f in cloud.fields]
    point = namedtuple("Point", field_names)
    return [point._make(values) for values in read_points(cloud, field_names, skip_nans, uvs)]


def create_cloud(header: Any, fields: Sequence[Any], points: Any) -> Any:
    """A PointCloud2 of one row holding ``points`` (one sequence of values per point, in the
    order of the fields sorted by offset; a 2-D numpy array is packed column by column)."""
    from minros.msgs import get_message_class

    fmt, items = _layout(False, fields)
    size = struct.calcsize(fmt)
    data = _pack(items, size, fmt, points)
    count = len(points)
    return get_message_class("sensor_msgs/PointCloud2")(
        header=header, height=1, width=count, is_dense=False, is_bigendian=False,
        fields=fields, point_step=size, row_step=size * count, data=data)


def _pack(items: Sequence[Tuple[str, int]], size: int, fmt: str, points: Any) -> bytes:
    """The points' bytes: a 2-D numpy array is packed a column at a time (when every column
    fits its field exactly); other points one at a time with ROS's struct format, so values
    struct refuses fail as in ROS."""
    import numpy

    count = len(points)
    if isinstance(points, numpy.ndarray) and points.ndim == 2 and points.shape[1] == len(items) \
            and count and _fits(points, items):
        records = numpy.zeros(count, dtype=_dtype(False, items, size))
        for i in range(len(items)):
            records[f"f{i}"] = points[:, i]
        return records.tobytes()
    cloud_struct = struct.Struct(fmt)
    buff = bytearray(size * count)
    offset = 0
    for p in points:
        cloud_struct.pack_into(buff, offset, *p)
        offset += size
    return bytes(buff)


def _fits(points: Any, items: Sequence[Tuple[str, int]]) -> bool:
    """Whether every column converts to its field without change (no float into an integer
    field, no integer out of its field's range)."""
    import numpy

    kind = points.dtype.kind
    if kind not in "iuf":
        return False
    for i, (code, _) in enumerate(items):
        if code in "fd":
            continue
        if kind == "f":
            return False
        info = numpy.iinfo(numpy.dtype(_NUMPY[code]))
        column = points[:, i]
        if column.min() < info.min or column.max() > info.max:
            return False
    return True


def create_cloud_xyz32(header: Any, points: Any) -> Any:
    """A PointCloud2 of float32 x, y, z."""
    from minros.msgs import get_message_class

    point_field = get_message_class("sensor_msgs/PointField")
    fields = [point_field("x", 0, point_field.FLOAT32, 1), point_field("y", 4, point_field.FLOAT32, 1),
              point_field("z", 8, point_field.FLOAT32, 1)]
    return create_cloud(header, fields, points)
