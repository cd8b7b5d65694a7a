"""The 3D view's server side without sockets: messages made into what the page draws
(scenedata), and tf placed into the fixed frame (SceneHub on a fake state)."""

from __future__ import annotations

import math

import numpy as np
import pytest

from minros.msgs import Time, get_message_class
from minros.point_cloud2 import create_cloud
from minros.web import scenedata
from minros.web.scene import SceneHub
from minros.web.scenedata import DisplayError

PointField = get_message_class("sensor_msgs/PointField")
LaserScan = get_message_class("sensor_msgs/LaserScan")
OccupancyGrid = get_message_class("nav_msgs/OccupancyGrid")
Marker = get_message_class("visualization_msgs/Marker")
Point = get_message_class("geometry_msgs/Point")
ColorRGBA = get_message_class("std_msgs/ColorRGBA")
TransformStamped = get_message_class("geometry_msgs/TransformStamped")
InteractiveMarker = get_message_class("visualization_msgs/InteractiveMarker")
InteractiveMarkerInit = get_message_class("visualization_msgs/InteractiveMarkerInit")
InteractiveMarkerUpdate = get_message_class("visualization_msgs/InteractiveMarkerUpdate")
InteractiveMarkerPose = get_message_class("visualization_msgs/InteractiveMarkerPose")
Header = get_message_class("std_msgs/Header")


def no_mesh(uri):
    return None, f"no package for {uri}"


def mesh(uri):
    return "/pkg/" + uri[len("package://"):], None


# -- binary frames -------------------------------------------------------------------------------

def test_a_binary_frame_holds_aligned_arrays_the_header_lists():
    xyz = np.arange(12, dtype=np.float32).reshape(4, 3)
    colors = np.array([[1, 2, 3]] * 4, np.uint8)
    frame = scenedata.pack({"op": "scene_data", "id": "d1"}, [("position", xyz), ("color", colors)])
    header, arrays = scenedata.unpack(frame)
    assert header["op"] == "scene_data" and header["id"] == "d1"
    starts = [entry["offset"] for entry in header["buffers"]]
    assert all(offset % 8 == 0 for offset in starts)
    assert arrays["position"].tolist() == xyz.ravel().tolist()
    assert arrays["color"].tolist() == colors.ravel().tolist()


def test_json_text_refuses_nan_with_a_reason():
    with pytest.raises(DisplayError, match="NaN or infinite"):
        scenedata.json_text({"pose": [float("nan")]})


# -- point clouds ----------------------------------------------------------------------------------

def fields(*specs):
    return [PointField(name=n, offset=o, datatype=d, count=1) for n, o, d in specs]


def packed_rgb(r, g, b):
    return np.array([(r << 16) | (g << 8) | b], np.uint32).view(np.float32)[0]


def test_a_cloud_with_rgb_gives_points_and_their_colours():
    cloud = create_cloud(Header(frame_id="cam"), fields(("x", 0, 7), ("y", 4, 7), ("z", 8, 7), ("rgb", 12, 7)),
                         [(1.0, 2.0, 3.0, packed_rgb(255, 0, 10)), (float("nan"), 0, 0, packed_rgb(0, 0, 0)),
                          (4.0, 5.0, 6.0, packed_rgb(0, 128, 255))])
    xyz, colors, info = scenedata.cloud_arrays(cloud)
    assert xyz.tolist() == [[1, 2, 3], [4, 5, 6]]
    assert colors.tolist() == [[255, 0, 10], [0, 128, 255]]
    assert info == {"color": "rgb", "dropped": 1, "total": 3}


def test_a_cloud_with_intensity_is_coloured_by_it_blue_to_red():
    cloud = create_cloud(Header(), fields(("x", 0, 7), ("y", 4, 7), ("z", 8, 7), ("intensity", 12, 7)),
                         [(0, 0, 0, 0.0), (1, 0, 0, 50.0), (2, 0, 0, 100.0)])
    _xyz, colors, info = scenedata.cloud_arrays(cloud)
    assert info["color"] == "intensity"
    assert colors[0].tolist() == [0, 0, 255] and colors[2].tolist() == [255, 0, 0]
    assert colors[1].tolist() == [0, 255, 0]


def test_a_cloud_with_padded_rows_and_big_endian_values():
    dtype = np.dtype([("x", ">f4"), ("y", ">f4"), ("z", ">f4")])
    rows = [np.array([(1, 2, 3), (4, 5, 6)], dtype).tobytes() + b"\xff" * 8,
            np.array([(7, 8, 9), (10, 11, 12)], dtype).tobytes() + b"\xff" * 8]
    PointCloud2 = get_message_class("sensor_msgs/PointCloud2")
    cloud = PointCloud2(height=2, width=2, fields=fields(("x", 0, 7), ("y", 4, 7), ("z", 8, 7)),
                        is_bigendian=True, point_step=12, row_step=32, data=b"".join(rows))
    xyz, _colors, info = scenedata.cloud_arrays(cloud)
    assert xyz.tolist() == [[1, 2, 3], [4, 5, 6], [7, 8, 9], [10, 11, 12]]
    assert info["color"] == "z"


def xyz_cloud(width, height):
    PointCloud2 = get_message_class("sensor_msgs/PointCloud2")
    index = np.arange(width * height, dtype=np.float32)
    points = np.stack([index % width, index // width, index], axis=1).astype(np.float32)
    return PointCloud2(height=height, width=width, fields=fields(("x", 0, 7), ("y", 4, 7), ("z", 8, 7)),
                       point_step=12, row_step=12 * width, data=points.tobytes())


def test_a_big_cloud_is_thinned_evenly_to_max_points():
    # unorganized: every (count / max)-th point, from the first to near the last
    xyz, colors, info = scenedata.cloud_arrays(xyz_cloud(100_000, 1), max_points=25_000)
    assert len(xyz) == len(colors) == 25_000 and info["total"] == 100_000
    assert xyz[:3, 0].tolist() == [0, 4, 8] and xyz[-1, 0] == 99_996
    # organized (an image's pixels): every k-th row and column, still a grid
    xyz, _colors, info = scenedata.cloud_arrays(xyz_cloud(640, 480), max_points=25_000)
    assert len(xyz) == 160 * 120 and info["total"] == 640 * 480
    assert sorted(set(xyz[:, 0].tolist()))[:3] == [0, 4, 8] and sorted(set(xyz[:, 1].tolist()))[:3] == [0, 4, 8]
    # a grid that would still be too big (2 rows) falls back to every n-th point
    assert len(scenedata.cloud_arrays(xyz_cloud(50_000, 2), max_points=25_000)[0]) == 25_000
    # 0, or no more points than the cloud has: all of them
    assert len(scenedata.cloud_arrays(xyz_cloud(1000, 1), max_points=0)[0]) == 1000
    assert len(scenedata.cloud_arrays(xyz_cloud(1000, 1), max_points=1000)[0]) == 1000
    # the colours are those of the points kept (the rainbow over z spans what is shown)
    xyz, colors, _info = scenedata.cloud_arrays(xyz_cloud(1000, 1), max_points=10)
    assert colors[0].tolist() == [0, 0, 255] and colors[-1].tolist() == [255, 0, 0]


@pytest.mark.parametrize("change, text", [
    (lambda c: setattr(c, "data", c.data[:-5]), "data holds"),
    (lambda c: setattr(c, "fields", c.fields[:2]), "no z field"),
    (lambda c: setattr(c, "row_step", 4), "row_step 4 is less than"),
    (lambda c: c.fields[2].__setattr__("offset", 100), "ends past point_step"),
    (lambda c: c.fields[0].__setattr__("datatype", 42), "datatype 42"),
])
def test_a_malformed_cloud_says_what_is_wrong(change, text):
    cloud = create_cloud(Header(), fields(("x", 0, 7), ("y", 4, 7), ("z", 8, 7)), [(1, 2, 3), (4, 5, 6)])
    change(cloud)
    with pytest.raises(DisplayError, match=text):
        scenedata.cloud_arrays(cloud)


# -- scans and grids -------------------------------------------------------------------------------

def test_a_scan_keeps_its_valid_ranges_as_points():
    scan = LaserScan(angle_min=0.0, angle_increment=math.pi / 2, range_min=0.1, range_max=10.0,
                     ranges=[1.0, float("inf"), 2.0, 0.05, 30.0])
    xyz, colors, info = scenedata.scan_arrays(scan)
    assert np.allclose(xyz, [[1, 0, 0], [-2, 0, 0]], atol=1e-6)
    assert colors is None and info["dropped"] == 3
    scan.intensities = [1.0, 2.0]
    with pytest.raises(DisplayError, match="2 intensities for 5 ranges"):
        scenedata.scan_arrays(scan)


def test_a_grid_is_one_byte_a_cell_unknown_255():
    grid = OccupancyGrid()
    grid.info.width, grid.info.height, grid.info.resolution = 3, 2, 0.05
    grid.info.origin.position.x = -1.0
    grid.data = [0, 100, -1, 50, 0, 0]
    meta, cells = scenedata.grid_cells(grid)
    assert meta["width"] == 3 and meta["height"] == 2 and meta["resolution"] == pytest.approx(0.05)
    assert meta["origin"] == [-1.0, 0, 0, 0, 0, 0, 1.0]  # a zero quaternion is the identity
    assert cells.tolist() == [0, 100, 255, 50, 0, 0]
    grid.data = grid.data[:5]
    with pytest.raises(DisplayError, match="5 cells for width 3 x height 2"):
        scenedata.grid_cells(grid)


# -- markers -------------------------------------------------------------------------------------

def test_every_marker_type_converts():
    for kind in range(12):
        marker = Marker(ns="all", id=kind, type=kind, action=Marker.ADD)
        marker.pose.orientation.w = 1.0
        marker.scale.x = marker.scale.y = marker.scale.z = 0.5
        marker.color = ColorRGBA(1, 0, 0, 1)
        marker.points = [Point(0, 0, 0), Point(1, 0, 0), Point(0, 1, 0)]
        marker.colors = [ColorRGBA(0, 1, 0, 1)] * 3
        marker.text = "hello"
        marker.mesh_resource = "package://robot_pkg/meshes/base.stl"
        entry = scenedata.marker_json(marker, mesh)
        assert entry["type"] == scenedata.MARKER_TYPES[kind]
        assert entry["points"] == [0, 0, 0, 1, 0, 0, 0, 1, 0]
        scenedata.json_text(entry)
        if kind == Marker.MESH_RESOURCE:
            assert entry["mesh"] == "/pkg/robot_pkg/meshes/base.stl"
        if kind == Marker.TEXT_VIEW_FACING:
            assert entry["text"] == "hello"


@pytest.mark.parametrize("setup, text", [
    (dict(type=42), "unknown type 42"),
    (dict(type=Marker.MESH_RESOURCE), "without a mesh_resource"),
    (dict(type=Marker.MESH_RESOURCE, mesh_resource="package://nowhere/a.stl"), "no package for"),
    (dict(type=Marker.POINTS, points=[Point()] * 2, colors=[ColorRGBA()]), "1 colors for 2 points"),
    (dict(type=Marker.CUBE, action=7), "unknown action 7"),
])
def test_a_bad_marker_says_which_and_why(setup, text):
    marker = Marker(ns="bad", id=3, **setup)
    with pytest.raises(DisplayError, match=text) as caught:
        scenedata.marker_json(marker, no_mesh)
    assert "bad/3" in str(caught.value)


def test_interactive_marker_updates_follow_their_sequence():
    state = scenedata.InteractiveMarkerState()
    first = InteractiveMarker(name="box")
    assert not state.update(InteractiveMarkerUpdate(server_id="s", seq_num=1, type=1))  # no init yet
    assert state.init(InteractiveMarkerInit(server_id="s", seq_num=1, markers=[first]))
    moved = InteractiveMarkerPose(name="box")
    moved.pose.position.x = 2.0
    assert state.update(InteractiveMarkerUpdate(server_id="s", seq_num=2, type=1, poses=[moved]))
    assert state.markers["box"].pose.position.x == 2.0
    assert not state.update(InteractiveMarkerUpdate(server_id="s", seq_num=2, type=1, erases=["box"]))
    # a skipped number: wait for an update_full at least that new
    assert not state.update(InteractiveMarkerUpdate(server_id="s", seq_num=4, type=1, erases=["box"]))
    assert not state.init(InteractiveMarkerInit(server_id="s", seq_num=3, markers=[]))
    assert state.init(InteractiveMarkerInit(server_id="s", seq_num=4, markers=[]))
    assert state.markers == {}


# -- the robot model -----------------------------------------------------------------------------

URDF = """<?xml version="1.0"?>
<robot name="bot">
  <material name="blue"><color rgba="0 0 0.8 1"/></material>
  <link name="base_link">
    <visual><origin xyz="0 0 0.1" rpy="0 0 1.5707963"/><geometry><box size="0.4 0.3 0.1"/></geometry>
      <material name="blue"/></visual>
  </link>
  <link name="wheel"><visual><geometry><cylinder radius="0.05" length="0.02"/></geometry>
      <material name="black"><color rgba="0 0 0 1"/></material></visual></link>
  <link name="head"><visual><geometry><sphere radius="0.1"/></geometry><material name="nope"/></visual></link>
  <link name="arm"><visual><geometry><mesh filename="package://robot_pkg/meshes/arm.dae" scale="2 2 2"/></geometry></visual>
    <visual><geometry><mesh filename="package://gone/x.stl"/></geometry></visual></link>
  <link name="base_footprint"/>
</robot>"""


def test_a_urdf_gives_each_links_visuals_and_the_problems():
    robot = scenedata.robot_json(URDF, lambda uri: mesh(uri) if "robot_pkg" in uri else no_mesh(uri))
    links = {link["name"]: link["visuals"] for link in robot["links"]}
    assert list(links) == ["base_link", "wheel", "head", "arm", "base_footprint"]
    base = links["base_link"][0]
    assert base["geometry"] == {"type": "box", "size": [0.4, 0.3, 0.1]}
    assert base["color"] == [0, 0, 0.8, 1]
    assert base["origin"][:3] == [0, 0, 0.1] and base["origin"][5] == pytest.approx(math.sqrt(0.5), abs=1e-6)
    assert links["wheel"][0]["color"] == [0, 0, 0, 1]
    assert links["arm"][0]["geometry"] == {"type": "mesh", "url": "/pkg/robot_pkg/meshes/arm.dae",
                                           "uri": "package://robot_pkg/meshes/arm.dae", "scale": [2, 2, 2]}
    assert len(links["arm"]) == 1
    assert any("material 'nope' is not defined" in p for p in robot["problems"])
    assert any("no package for package://gone/x.stl" in p for p in robot["problems"])
    with pytest.raises(DisplayError, match="not valid XML"):
        scenedata.robot_json("<robot><link>", mesh)


def test_compose_and_invert_are_inverse():
    a = [1.0, 2.0, 3.0, *np.array([0.1, 0.2, 0.3, 0.9]) / np.linalg.norm([0.1, 0.2, 0.3, 0.9])]
    b = [0.5, -1.0, 2.0, 0.0, 0.0, math.sin(0.4), math.cos(0.4)]
    back = scenedata.compose(scenedata.invert(a), scenedata.compose(a, b))
    assert np.allclose(back[:3], b[:3]) and abs(abs(np.dot(back[3:], b[3:])) - 1) < 1e-9


# -- tf into the fixed frame -----------------------------------------------------------------------

def transform(parent, child, x, stamp, yaw=0.0):
    t = TransformStamped()
    t.header.frame_id, t.child_frame_id, t.header.stamp = parent, child, Time(stamp, 0)
    t.transform.translation.x = x
    t.transform.rotation.z, t.transform.rotation.w = math.sin(yaw / 2), math.cos(yaw / 2)
    return t


def test_the_hub_places_frames_into_the_fixed_frame_and_ages_them():
    now = [100.0]
    hub = SceneHub(state=None, clock=lambda: now[0])
    hub.add([transform("map", "odom", 1.0, 10)], "/sim", static=True)
    hub.add([transform("odom", "base_link", 2.0, 10), transform("odom", "base_link", 4.0, 12)], "/sim", static=False)
    pose, warning = hub.lookup("map", "base_link", Time(11, 0))
    assert pose[0] == pytest.approx(4.0) and warning == ""  # 1 + lerp(2, 4) at 11
    pose, warning = hub.lookup("map", "base_link", Time(50, 0))  # data newer than tf: latest
    assert pose[0] == pytest.approx(5.0) and warning == ""
    pose, warning = hub.lookup("map", "base_link", Time(1, 0))  # older than tf: latest, said
    assert pose[0] == pytest.approx(5.0) and "past" in warning
    with pytest.raises(Exception, match=r"No transform from \[camera\] to \[map\]: .*does not exist"):
        hub.lookup("map", "camera", Time(11, 0))
    with pytest.raises(Exception, match="frame_id is empty"):
        hub.lookup("map", "", Time(11, 0))
    now[0] += 10.0
    frames = {f["name"]: f for f in hub.frames_json("map")["frames"]}
    assert frames["base_link"]["T"][0] == pytest.approx(5.0) and frames["base_link"]["stale"]
    assert not frames["odom"]["stale"] and frames["map"]["T"] == [0, 0, 0, 0, 0, 0, 1]
    assert hub.frames_json("world")["error"] == "Fixed Frame [world] does not exist"
    assert "no tf received" in SceneHub(state=None).frames_json("map")["warning"]


# -- the view's ops on a page session ------------------------------------------------------------

def test_display_ops_check_what_the_page_asks():
    import json

    from test_web_page import replies, session

    page, outbox, state = session()
    page.receive(json.dumps({"op": "scene_watch", "id": "w", "fixed": " "}))
    assert "the fixed frame is empty" in replies(outbox)[0]["msg"]
    page.receive(json.dumps({"op": "display_add", "id": "a", "topic": "/nowhere"}))
    assert replies(outbox) == [{"op": "reply", "id": "a",
                                "error": "topic /nowhere does not exist (or has no type yet)"}]
    # a topic not published yet, with the kind the page expects: tapped, waiting
    page.receive(json.dumps({"op": "display_add", "id": "b", "topic": "/scan_later", "kind": "scan"}))
    assert replies(outbox) == [{"op": "reply", "id": "b", "kind": "scan", "type": "",
                                "topic": "/scan_later"}]
    assert state.tapped == [("/scan_later", ("page", "test", "scene", "b"))]
    page.receive(json.dumps({"op": "display_add", "id": "c", "topic": "/turtle1/pose"}))
    error = replies(outbox)[0]["error"]
    assert error.startswith("/turtle1/pose is a turtlesim/Pose: the 3D view shows ")
    page.receive(json.dumps({"op": "display_remove", "id": "b"}))
    assert state.tapped == []
    # a cloud's max_points: a count of points, 0 for all
    page.receive(json.dumps({"op": "display_add", "id": "d", "topic": "/cloud_later", "kind": "cloud",
                             "max_points": 25000}))
    assert replies(outbox)[0]["kind"] == "cloud" and page.scene.displays["d"].max_points == 25000
    for bad, text in ((-1, "max_points must be a number of points (0: all), not -1"),
                      ("all", "Expected field max_points to be one of ('int',)")):
        page.receive(json.dumps({"op": "display_add", "id": "e", "topic": "/cloud_later", "kind": "cloud",
                                 "max_points": bad}))
        assert text in replies(outbox)[0]["msg"]
    page.receive(json.dumps({"op": "display_remove", "id": "d"}))
    page.receive(json.dumps({"op": "im_feedback", "id": "nope", "marker": "m", "event": 1}))
    assert "no interactive marker display nope" in replies(outbox)[0]["msg"]
    page.close()


class FakeIncoming:
    def __init__(self, msg, type_name):
        self.msg = msg
        self.tap = type("Tap", (), {"type": type_name, "topic": "/t"})()
        self._cache = {}

    def decoded(self):
        return self.msg

    def cached(self, key, make):
        if key not in self._cache:
            self._cache[key] = make()
        return self._cache[key]


def test_a_display_renders_binary_clouds_placed_by_tf_and_each_status_once():
    import json

    from minros.web.scene import Display

    hub = SceneHub(state=None)
    hub.add([transform("map", "cam", 2.0, 10)], "/x", static=True)
    session = type("Session", (), {"hub": hub, "fixed": "map", "mesh_url": staticmethod(mesh)})()
    display = Display(session, "d1", "cloud", "/t", "sensor_msgs/PointCloud2")
    cloud = create_cloud(Header(frame_id="cam", stamp=Time(10, 0)), fields(("x", 0, 7), ("y", 4, 7), ("z", 8, 7)),
                         [(1, 2, 3), (4, 5, 6)])
    status, frame = display.render(FakeIncoming(cloud, "sensor_msgs/PointCloud2"))
    assert json.loads(status) == {"op": "scene_status", "id": "d1", "level": "ok", "text": ""}
    header, arrays = scenedata.unpack(frame)
    assert header["frame"] == "cam" and header["T"][0] == pytest.approx(2.0) and header["fixed"] == "map"
    assert header["count"] == 2 and arrays["position"].tolist() == [1, 2, 3, 4, 5, 6]
    assert display.render(FakeIncoming(cloud, "sensor_msgs/PointCloud2"))[0] == frame  # no new status
    display.max_points = 1  # thinned, and said how many the message had
    header, arrays = scenedata.unpack(display.render(FakeIncoming(cloud, "sensor_msgs/PointCloud2"))[0])
    assert header["count"] == 1 and header["total"] == 2 and arrays["position"].tolist() == [1, 2, 3]
    display.max_points = 0
    cloud.data = cloud.data[:-4]
    (bad,) = display.render(FakeIncoming(cloud, "sensor_msgs/PointCloud2"))
    assert json.loads(bad)["level"] == "error" and "data holds 20 bytes" in json.loads(bad)["text"]
    assert display.render(FakeIncoming(cloud, "sensor_msgs/PointCloud2")) == []  # said once
    cloud.header.frame_id = "elsewhere"
    (lost,) = display.render(FakeIncoming(cloud, "sensor_msgs/PointCloud2"))
    assert json.loads(lost)["text"].startswith("No transform from [elsewhere] to [map]")
    (wrong,) = display.render(FakeIncoming(cloud, "sensor_msgs/LaserScan"))
    assert "/t is a sensor_msgs/LaserScan, not what a cloud display shows" in json.loads(wrong)["text"]


def test_time_going_back_clears_the_transforms_but_not_the_static_ones():
    hub = SceneHub(state=None)
    hub.add([transform("map", "odom", 1.0, 100)], "/x", static=True)
    hub.add([transform("odom", "base", 5.0, 100)], "/x", static=False)
    assert hub.lookup("map", "base")[0][0] == pytest.approx(6.0)
    hub.add([transform("odom", "base", 2.0, 10)], "/x", static=False)  # a simulation restarted
    assert hub.lookup("map", "base", Time(10, 0))[0][0] == pytest.approx(3.0)
    assert hub.lookup("map", "odom")[0][0] == pytest.approx(1.0)
