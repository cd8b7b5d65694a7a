"""What the page's 3D view is sent: ROS messages made into what the browser draws (pure).

The server does the work a browser cannot do cheaply, and the browser only hands arrays to
WebGL: a PointCloud2's fields are read with numpy into float32 positions and 8-bit colours
(RGB8 from an ``rgb``/``rgba`` field, Rviz's rainbow over ``intensity``, else over z), a
LaserScan's ranges become points, an OccupancyGrid's cells one byte each; those travel as
binary frames (:func:`pack`). Markers, paths, poses, polygons, the robot model of a URDF and
interactive markers are small and travel as JSON (:func:`json_text`, which refuses NaN, as
JSON has none).

Poses are 7 numbers ``[x, y, z, qx, qy, qz, qw]``; a quaternion of zeros (a default message)
is taken as the identity, as Rviz does, and any other is normalised. A message that cannot be
shown raises :class:`DisplayError`, whose text is shown in the display list.

No sockets, no ROS: messages in (anything with the fields), numbers out.
"""

from __future__ import annotations

import json
import math
import struct
import xml.etree.ElementTree as ET
from typing import Any, Callable, Dict, List, Optional, Sequence, Tuple

import numpy as np

from minros.urdf_model import rpy_to_quaternion

#: a URL the page can load for a mesh or texture URI, or None and why not
MeshUrl = Callable[[str], Tuple[Optional[str], Optional[str]]]

# visualization_msgs/Marker types and actions
ARROW, CUBE, SPHERE, CYLINDER, LINE_STRIP, LINE_LIST, CUBE_LIST, SPHERE_LIST, POINTS, \
    TEXT_VIEW_FACING, MESH_RESOURCE, TRIANGLE_LIST = range(12)
MARKER_TYPES = {ARROW: "arrow", CUBE: "cube", SPHERE: "sphere", CYLINDER: "cylinder",
                LINE_STRIP: "line_strip", LINE_LIST: "line_list", CUBE_LIST: "cube_list",
                SPHERE_LIST: "sphere_list", POINTS: "points", TEXT_VIEW_FACING: "text",
                MESH_RESOURCE: "mesh", TRIANGLE_LIST: "triangle_list"}
ADD, DELETE, DELETEALL = 0, 2, 3
#: sensor_msgs/PointField datatypes -> numpy types
FIELD_TYPES = {1: "i1", 2: "u1", 3: "i2", 4: "u2", 5: "i4", 6: "u4", 7: "f4", 8: "f8"}
FIELD_SIZES = {1: 1, 2: 1, 3: 2, 4: 2, 5: 4, 6: 4, 7: 4, 8: 8}
#: the largest grid side shown (WebGL textures of software renderers stop at 8192)
MAX_GRID_SIDE = 8192
IDENTITY = [0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 1.0]


class DisplayError(ValueError):
    """A message the view cannot show; the text says what is wrong with it."""


# -- frames sent to the page ---------------------------------------------------------------

_LENGTH = struct.Struct("<I")


def json_text(obj: Dict[str, Any]) -> str:
    """``obj`` as JSON; DisplayError when it holds NaN or an infinity."""
    try:
        return json.dumps(obj, allow_nan=False, separators=(",", ":"))
    except ValueError:
        raise DisplayError("the message contains NaN or infinite values (check the "
                           "publisher's poses, scales and points)") from None


def pack(header: Dict[str, Any], arrays: Sequence[Tuple[str, np.ndarray]]) -> bytes:
    """A binary frame: its JSON header's length (uint32, little-endian), the header, zeros to
    a multiple of 8 bytes, then each array's bytes, each padded to 8. The header lists the
    arrays (``buffers``: name, numpy type, offset from the start of the data, length in
    elements), so the browser makes typed arrays over the frame without copying."""
    buffers = []
    offset = 0
    blobs = []
    for name, array in arrays:
        array = np.ascontiguousarray(array)
        if array.dtype.byteorder == ">":
            array = array.astype(array.dtype.newbyteorder("<"))
        data = array.tobytes()
        buffers.append({"name": name, "type": array.dtype.str.lstrip("<|="),
                        "offset": offset, "length": int(array.size)})
        blobs.append(data + b"\0" * (-len(data) % 8))
        offset += len(blobs[-1])
    head = json.dumps({**header, "buffers": buffers}, allow_nan=False,
                      separators=(",", ":")).encode("utf-8")
    start = _LENGTH.pack(len(head)) + head
    return b"".join([start, b"\0" * (-len(start) % 8), *blobs])


def unpack(frame: bytes) -> Tuple[Dict[str, Any], Dict[str, np.ndarray]]:
    """The header and arrays of a frame made by :func:`pack` (what the browser does)."""
    (length,) = _LENGTH.unpack_from(frame)
    header = json.loads(frame[4:4 + length])
    base = 4 + length + (-(4 + length) % 8)
    arrays = {}
    for entry in header["buffers"]:
        dtype = np.dtype(entry["type"])
        start = base + entry["offset"]
        arrays[entry["name"]] = np.frombuffer(frame, dtype, entry["length"], start)
    return header, arrays


# -- poses ---------------------------------------------------------------------------------

def pose7(pose: Any) -> List[float]:
    """A geometry_msgs/Pose as ``[x, y, z, qx, qy, qz, qw]`` (quaternion normalised)."""
    p, q = pose.position, pose.orientation
    return [float(p.x), float(p.y), float(p.z), *quaternion4(q)]


def quaternion4(q: Any) -> List[float]:
    x, y, z, w = float(q.x), float(q.y), float(q.z), float(q.w)
    norm = math.sqrt(x * x + y * y + z * z + w * w)
    if norm == 0.0:  # a default message: Rviz takes it as the identity too
        return [0.0, 0.0, 0.0, 1.0]
    if not math.isfinite(norm):
        return [x, y, z, w]  # json_text refuses it, with the reason
    return [x / norm, y / norm, z / norm, w / norm]


def transform7(transform: Any) -> List[float]:
    """A geometry_msgs/TransformStamped's transform as 7 numbers."""
    t, q = transform.transform.translation, transform.transform.rotation
    return [float(t.x), float(t.y), float(t.z), float(q.x), float(q.y), float(q.z), float(q.w)]


def rgba(color: Any) -> List[float]:
    return [float(color.r), float(color.g), float(color.b), float(color.a)]


# -- colour maps ---------------------------------------------------------------------------

def rainbow(values: np.ndarray) -> np.ndarray:
    """Rviz's rainbow over ``values`` scaled to their range: blue (low) through cyan, green,
    yellow to red (high), as (n, 3) uint8."""
    values = np.asarray(values, dtype=np.float64)
    finite = np.isfinite(values)
    low = float(values[finite].min()) if finite.any() else 0.0
    high = float(values[finite].max()) if finite.any() else 1.0
    span = high - low if high > low else 1.0
    t = np.clip(np.where(finite, (values - low) / span, 0.0), 0.0, 1.0) * 4.0
    r = np.clip(t - 2.0, 0.0, 1.0)
    g = np.clip(np.minimum(t, 4.0 - t), 0.0, 1.0)
    b = np.clip(2.0 - t, 0.0, 1.0)
    return (np.stack([r, g, b], axis=1) * 255.0 + 0.5).astype(np.uint8)


# -- point clouds and scans ----------------------------------------------------------------

def thin(count: int, width: int, height: int, max_points: int) -> Optional[np.ndarray]:
    """The indices of at most ``max_points`` of a cloud's ``count`` points spread evenly over
    it, or None to keep them all (``max_points`` 0, or not fewer than ``count``). An organized
    cloud (``height`` > 1: an image's pixels) keeps every k-th row and every k-th column, so the
    picture stays a regular grid; any other, every (count / max_points)-th point."""
    if max_points <= 0 or count <= max_points:
        return None
    if height > 1:
        k = math.ceil(math.sqrt(count / max_points))
        grid = np.arange(count).reshape(height, width)[::k, ::k].ravel()
        if len(grid) <= max_points:
            return grid
    return np.arange(max_points, dtype=np.int64) * count // max_points


def cloud_arrays(msg: Any, max_points: int = 0) -> Tuple[np.ndarray, np.ndarray, Dict[str, Any]]:
    """A sensor_msgs/PointCloud2's finite points as float32 (n, 3) and their colours as uint8
    (n, 3), with what was done (``color``: rgb, intensity or z; ``dropped`` invalid points;
    ``total`` points in the message). With ``max_points``, at most that many of its points
    (see :func:`thin`): a software renderer draws a 100,000-point cloud at a few frames per
    second, a quarter of it smoothly, and the server converts and sends only what is drawn."""
    width, height, step, row_step = int(msg.width), int(msg.height), int(msg.point_step), int(msg.row_step)
    fields = {f.name: f for f in msg.fields}
    missing = [name for name in ("x", "y", "z") if name not in fields]
    if missing:
        raise DisplayError(f"PointCloud2 has no {', '.join(missing)} field (fields: "
                           f"{', '.join(fields) or 'none'}): nothing to place")
    data = msg.data if isinstance(msg.data, (bytes, bytearray, memoryview)) else bytes(msg.data)
    count = width * height
    if count == 0:
        return (np.zeros((0, 3), np.float32), np.zeros((0, 3), np.uint8),
                {"color": "none", "dropped": 0, "total": 0})
    if row_step < width * step:
        raise DisplayError(f"PointCloud2 row_step {row_step} is less than width {width} x "
                           f"point_step {step}")
    if len(data) < row_step * (height - 1) + width * step:
        raise DisplayError(f"PointCloud2 data holds {len(data)} bytes; width {width}, height "
                           f"{height}, point_step {step} and row_step {row_step} need "
                           f"{row_step * height}")
    names, formats, offsets = [], [], []
    order = ">" if msg.is_bigendian else "<"
    for name, field in fields.items():
        if field.datatype not in FIELD_TYPES or int(field.count) < 1:
            continue
        if int(field.offset) + FIELD_SIZES[field.datatype] > step:
            if name in ("x", "y", "z"):
                raise DisplayError(f"PointCloud2 field {name} (offset {field.offset}) ends past "
                                   f"point_step {step}")
            continue
        names.append(name)
        formats.append(order + FIELD_TYPES[field.datatype])
        offsets.append(int(field.offset))
    for name in ("x", "y", "z"):
        if name not in names:
            raise DisplayError(f"PointCloud2 field {name} has datatype {fields[name].datatype}, "
                               "not one of sensor_msgs/PointField's (1-8)")
    dtype = np.dtype({"names": names, "formats": formats, "offsets": offsets, "itemsize": step})
    if row_step == width * step:
        points = np.frombuffer(data, dtype, count)
    else:
        rows = np.frombuffer(data, np.uint8, row_step * (height - 1) + width * step)
        rows = np.lib.stride_tricks.as_strided(rows, (height, width * step), (row_step, 1))
        points = np.frombuffer(np.ascontiguousarray(rows).tobytes(), dtype, count)
    total = count
    kept = thin(count, width, height, max_points)
    if kept is not None:  # before anything is converted: only what is kept costs
        points = points[kept]
        count = len(points)
    xyz = np.empty((count, 3), np.float32)
    xyz[:, 0], xyz[:, 1], xyz[:, 2] = points["x"], points["y"], points["z"]
    finite = np.isfinite(xyz)
    valid = finite[:, 0] & finite[:, 1] & finite[:, 2]
    dropped = count - int(np.count_nonzero(valid))
    if dropped:
        xyz, points = xyz[valid], points[valid]
    color_name = next((n for n in ("rgb", "rgba") if n in names and
                       FIELD_SIZES[fields[n].datatype] == 4), None)
    if color_name is not None:
        # 0x00RRGGBB as a little-endian uint32 is the bytes B, G, R, 0
        packed = np.ascontiguousarray(points[color_name]).view(order + "u4").astype("<u4")
        colors = packed.view(np.uint8).reshape(-1, 4)[:, 2::-1]
        how = "rgb"
    elif "intensity" in names:
        colors, how = rainbow(points["intensity"]), "intensity"
    else:
        colors, how = rainbow(xyz[:, 2]), "z"
    return xyz, colors, {"color": how, "dropped": dropped, "total": total}


def scan_arrays(msg: Any) -> Tuple[np.ndarray, Optional[np.ndarray], Dict[str, Any]]:
    """A sensor_msgs/LaserScan's valid ranges (range_min..range_max, finite) as points in the
    scan's frame, coloured by intensity when it has one per range."""
    ranges = np.asarray(msg.ranges, dtype=np.float32)
    increment, start = float(msg.angle_increment), float(msg.angle_min)
    if not (math.isfinite(increment) and math.isfinite(start)):
        raise DisplayError("LaserScan angle_min or angle_increment is not a finite number")
    intensities = np.asarray(msg.intensities, dtype=np.float32)
    if len(intensities) not in (0, len(ranges)):
        raise DisplayError(f"LaserScan has {len(intensities)} intensities for {len(ranges)} "
                           "ranges (there must be none or one per range)")
    angles = start + increment * np.arange(len(ranges), dtype=np.float64)
    with np.errstate(invalid="ignore"):
        valid = np.isfinite(ranges) & (ranges >= msg.range_min) & (ranges <= msg.range_max)
    r = ranges[valid].astype(np.float64)
    xyz = np.zeros((len(r), 3), np.float32)
    xyz[:, 0] = r * np.cos(angles[valid])
    xyz[:, 1] = r * np.sin(angles[valid])
    colors = rainbow(intensities[valid]) if len(intensities) else None
    return xyz, colors, {"color": "intensity" if colors is not None else "flat",
                         "dropped": int(len(ranges) - valid.sum())}


# -- maps ----------------------------------------------------------------------------------

def grid_cells(msg: Any) -> Tuple[Dict[str, Any], np.ndarray]:
    """A nav_msgs/OccupancyGrid's geometry and its cells as bytes (-1, unknown, is 255)."""
    info = msg.info
    width, height, resolution = int(info.width), int(info.height), float(info.resolution)
    if not (math.isfinite(resolution) and resolution > 0):
        raise DisplayError(f"OccupancyGrid resolution {resolution} is not a positive number")
    if len(msg.data) != width * height:
        raise DisplayError(f"OccupancyGrid holds {len(msg.data)} cells for width {width} x "
                           f"height {height} = {width * height}")
    if max(width, height) > MAX_GRID_SIDE:
        raise DisplayError(f"OccupancyGrid is {width} x {height} cells; the view shows grids "
                           f"up to {MAX_GRID_SIDE} cells a side")
    data = msg.data
    if isinstance(data, (bytes, bytearray)):
        cells = np.frombuffer(data, np.uint8)
    else:
        cells = np.asarray(data, dtype=np.int16).astype(np.uint8)
    return ({"width": width, "height": height, "resolution": resolution,
             "origin": pose7(info.origin)}, cells)


# -- small messages ------------------------------------------------------------------------

def path_json(msg: Any) -> Dict[str, Any]:
    points = []
    for stamped in msg.poses:
        p = stamped.pose.position
        points += [float(p.x), float(p.y), float(p.z)]
    return {"points": points}


def pose_array_json(msg: Any) -> Dict[str, Any]:
    return {"poses": [pose7(p) for p in msg.poses]}


def polygon_json(msg: Any) -> Dict[str, Any]:
    points = []
    for p in msg.polygon.points:
        points += [float(p.x), float(p.y), float(p.z)]
    return {"points": points}


# -- markers -------------------------------------------------------------------------------

def marker_json(marker: Any, mesh_url: MeshUrl) -> Dict[str, Any]:
    """One visualization_msgs/Marker as the page draws it (its frame and pose are sent too)."""
    action = int(marker.action)
    out: Dict[str, Any] = {"ns": marker.ns, "id": int(marker.id), "action": action}
    if action in (DELETE, DELETEALL):
        return out
    if action != ADD:
        raise DisplayError(f"marker {marker.ns}/{marker.id}: unknown action {action} (ADD 0, "
                           "DELETE 2, DELETEALL 3)")
    kind = MARKER_TYPES.get(int(marker.type))
    if kind is None:
        raise DisplayError(f"marker {marker.ns}/{marker.id}: unknown type {marker.type} "
                           "(visualization_msgs/Marker's are 0 to 11)")
    s = marker.scale
    out.update(type=kind, pose=pose7(marker.pose), scale=[float(s.x), float(s.y), float(s.z)],
               color=rgba(marker.color), frame_locked=bool(marker.frame_locked),
               lifetime=marker.lifetime.secs + marker.lifetime.nsecs * 1e-9)
    if marker.points:
        flat: List[float] = []
        for p in marker.points:
            flat += [float(p.x), float(p.y), float(p.z)]
        out["points"] = flat
    if marker.colors:
        flat = []
        for c in marker.colors:
            flat += [float(c.r), float(c.g), float(c.b), float(c.a)]
        out["colors"] = flat
    if kind == "text":
        out["text"] = marker.text
    if kind == "mesh":
        if not marker.mesh_resource:
            raise DisplayError(f"marker {marker.ns}/{marker.id}: MESH_RESOURCE without a "
                               "mesh_resource URL")
        url, problem = mesh_url(marker.mesh_resource)
        if url is None:
            raise DisplayError(f"marker {marker.ns}/{marker.id}: {problem}")
        out["mesh"] = url
        out["embedded_materials"] = bool(marker.mesh_use_embedded_materials)
    if kind in ("line_strip", "line_list", "cube_list", "sphere_list", "points",
                "triangle_list") and marker.colors and len(marker.colors) != len(marker.points):
        raise DisplayError(f"marker {marker.ns}/{marker.id}: {len(marker.colors)} colors for "
                           f"{len(marker.points)} points (none or one per point)")
    return out


# -- interactive markers -------------------------------------------------------------------

def imarker_json(marker: Any, mesh_url: MeshUrl) -> Dict[str, Any]:
    """A visualization_msgs/InteractiveMarker: its pose, scale and controls (each with its
    axis orientation, modes and markers, whose poses are relative to the interactive
    marker's when they name no frame)."""
    controls = []
    for control in marker.controls:
        markers = []
        for item in control.markers:
            entry = marker_json(item, mesh_url)
            entry["frame"] = item.header.frame_id
            markers.append(entry)
        controls.append({
            "name": control.name, "orientation": quaternion4(control.orientation),
            "orientation_mode": int(control.orientation_mode),
            "interaction_mode": int(control.interaction_mode),
            "always_visible": bool(control.always_visible),
            "independent": bool(control.independent_marker_orientation),
            "description": control.description, "markers": markers})
    return {"name": marker.name, "description": marker.description, "pose": pose7(marker.pose),
            "scale": float(marker.scale) or 1.0, "controls": controls,
            "menu": [{"id": int(e.id), "parent": int(e.parent_id), "title": e.title}
                     for e in marker.menu_entries]}


class InteractiveMarkerState:
    """An interactive marker client's view of one server (interactive_markers' protocol): the
    markers of the latest ``update_full``, then each ``update`` in sequence; an update that
    skips a number waits for an ``update_full`` at least that new."""

    KEEP_ALIVE, UPDATE = 0, 1

    def __init__(self) -> None:
        self.server_id: Optional[str] = None
        self.seq: Optional[int] = None  # None: waiting for update_full
        self.wanted = 0
        self.markers: Dict[str, Any] = {}

    def init(self, msg: Any) -> bool:
        """Apply an InteractiveMarkerInit; True when the markers changed."""
        seq = int(msg.seq_num)
        if self.server_id is not None and msg.server_id != self.server_id:
            self.seq = None  # another server took over the topics (restarted)
        if self.seq is not None and seq <= self.seq or seq < self.wanted:
            return False
        self.server_id = msg.server_id
        self.seq = seq
        self.markers = {m.name: m for m in msg.markers}
        return True

    def update(self, msg: Any) -> bool:
        """Apply an InteractiveMarkerUpdate; True when the markers changed."""
        seq = int(msg.seq_num)
        if self.seq is None or msg.server_id != self.server_id:
            return False
        if int(msg.type) == self.KEEP_ALIVE:
            if seq > self.seq:  # updates were missed
                self.seq, self.wanted = None, seq
            return False
        if seq <= self.seq:
            return False
        if seq != self.seq + 1:
            self.seq, self.wanted = None, seq
            return False
        self.seq = seq
        for marker in msg.markers:
            self.markers[marker.name] = marker
        for pose in msg.poses:
            current = self.markers.get(pose.name)
            if current is not None:
                current.pose = pose.pose
                current.header = pose.header
        for name in msg.erases:
            self.markers.pop(name, None)
        return True


# -- the robot model -----------------------------------------------------------------------

def robot_json(urdf: str, mesh_url: MeshUrl) -> Dict[str, Any]:
    """The visuals of a URDF robot, by link (each link is drawn at its tf frame): geometry
    (box, cylinder, sphere, mesh with its page URL and scale), origin and colour, plus the
    problems found (a mesh the page cannot load, a material never defined)."""
    try:
        root = ET.fromstring(urdf)
    except ET.ParseError as exc:
        raise DisplayError(f"the robot description is not valid XML: {exc}") from None
    if root.tag != "robot":
        raise DisplayError(f"the robot description's root element is <{root.tag}>, not <robot>")
    problems: List[str] = []
    materials: Dict[str, Dict[str, Any]] = {}
    for element in root.findall("material"):
        name = element.get("name", "")
        materials[name] = _material(element, mesh_url, problems)
    links = []
    for link in root.findall("link"):
        name = link.get("name")
        if not name:
            problems.append("a <link> has no name: skipped")
            continue
        visuals = []
        for visual in link.findall("visual"):
            try:
                entry = _visual(visual, materials, mesh_url, problems, name)
            except DisplayError as exc:
                problems.append(str(exc))
                continue
            if entry is not None:
                visuals.append(entry)
        links.append({"name": name, "visuals": visuals})
    return {"name": root.get("name", ""), "links": links, "problems": problems}


def _floats(text: Optional[str], count: int, default: Sequence[float], where: str) -> List[float]:
    if text is None:
        return list(default)
    try:
        values = [float(v) for v in text.split()]
    except ValueError:
        raise DisplayError(f"{where}: {text!r} is not {count} numbers") from None
    if len(values) != count or not all(math.isfinite(v) for v in values):
        raise DisplayError(f"{where}: {text!r} is not {count} finite numbers")
    return values


def _material(element: ET.Element, mesh_url: MeshUrl, problems: List[str]) -> Dict[str, Any]:
    out: Dict[str, Any] = {}
    color = element.find("color")
    if color is not None:
        try:
            out["color"] = _floats(color.get("rgba"), 4, [1, 1, 1, 1],
                                   f"material {element.get('name', '')} color")
        except DisplayError as exc:
            problems.append(str(exc))
    texture = element.find("texture")
    if texture is not None and texture.get("filename"):
        url, problem = mesh_url(texture.get("filename", ""))
        if url is None:
            problems.append(f"material {element.get('name', '')}: {problem}")
        else:
            out["texture"] = url
    return out


def _visual(visual: ET.Element, materials: Dict[str, Dict[str, Any]], mesh_url: MeshUrl,
            problems: List[str], link: str) -> Optional[Dict[str, Any]]:
    where = f"link {link}"
    origin = visual.find("origin")
    xyz = _floats(origin.get("xyz") if origin is not None else None, 3, [0, 0, 0], f"{where} origin xyz")
    rpy = _floats(origin.get("rpy") if origin is not None else None, 3, [0, 0, 0], f"{where} origin rpy")
    geometry = visual.find("geometry")
    shape = geometry[0] if geometry is not None and len(geometry) else None
    if shape is None:
        raise DisplayError(f"{where}: a <visual> without a <geometry> shape")
    if shape.tag == "box":
        geo: Dict[str, Any] = {"type": "box", "size": _floats(shape.get("size"), 3, [0, 0, 0], f"{where} box size")}
    elif shape.tag == "cylinder":
        geo = {"type": "cylinder",
               "radius": _floats(shape.get("radius"), 1, [0], f"{where} cylinder radius")[0],
               "length": _floats(shape.get("length"), 1, [0], f"{where} cylinder length")[0]}
    elif shape.tag == "sphere":
        geo = {"type": "sphere", "radius": _floats(shape.get("radius"), 1, [0], f"{where} sphere radius")[0]}
    elif shape.tag == "mesh":
        filename = shape.get("filename", "")
        url, problem = mesh_url(filename) if filename else (None, "a <mesh> without a filename")
        if url is None:
            raise DisplayError(f"{where}: {problem}")
        geo = {"type": "mesh", "url": url, "uri": filename,
               "scale": _floats(shape.get("scale"), 3, [1, 1, 1], f"{where} mesh scale")}
    else:
        raise DisplayError(f"{where}: geometry <{shape.tag}> is not drawn (box, cylinder, "
                           "sphere and mesh are)")
    entry: Dict[str, Any] = {"origin": xyz + list(rpy_to_quaternion(*rpy)), "geometry": geo}
    material = visual.find("material")
    if material is not None:
        defined = _material(material, mesh_url, problems)
        if not defined:
            name = material.get("name", "")
            defined = materials.get(name, {})
            if name not in materials:
                problems.append(f"{where}: material {name!r} is not defined")
        entry.update(defined)
    return entry


# -- pose arithmetic -----------------------------------------------------------------------

def _qmul(a: Sequence[float], b: Sequence[float]) -> List[float]:
    ax, ay, az, aw = a
    bx, by, bz, bw = b
    return [aw * bx + ax * bw + ay * bz - az * by, aw * by - ax * bz + ay * bw + az * bx,
            aw * bz + ax * by - ay * bx + az * bw, aw * bw - ax * bx - ay * by - az * bz]


def _rotate(q: Sequence[float], v: Sequence[float]) -> List[float]:
    x, y, z = _qmul(_qmul(q, [v[0], v[1], v[2], 0.0]), [-q[0], -q[1], -q[2], q[3]])[:3]
    return [x, y, z]


def compose(a: Sequence[float], b: Sequence[float]) -> List[float]:
    """The pose ``a * b`` (``b`` expressed in ``a``'s frame, brought to ``a``'s parent)."""
    moved = _rotate(a[3:], b[:3])
    return [a[0] + moved[0], a[1] + moved[1], a[2] + moved[2], *_qmul(a[3:], b[3:])]


def invert(a: Sequence[float]) -> List[float]:
    q = [-a[3], -a[4], -a[5], a[6]]
    moved = _rotate(q, a[:3])
    return [-moved[0], -moved[1], -moved[2], *q]
