"""Test-only sources for the 3D view's browser tests: one node publishing what Rviz shows.

    scene_sources.py [--robot] [--markers] [--scan HZ] [--cloud POINTS] [--cloud-rate HZ]
                     [--map] [--nav] [--bad] [--imarker] [--all]

--robot       /robot_description (tests/web/scene_pkg's URDF: box, cylinders, sphere, STL, DAE
              and OBJ meshes) and tf: map -> odom (static), odom -> base_footprint (the robot
              drives a circle of 1 m, 20 Hz), the links (static), and map -> "old_sensor", sent
              on /tf once to each new subscriber (so it goes stale); a second robot as
              minros sim names several (/second/robot_description, /second/tf_prefix
              "second", frames second/...), standing at (-1, 2)
--markers     /markers (MarkerArray): every Marker type in a row along y at x 4 in map (ns "shapes"),
              their names (ns "labels"), a frame-locked arrow on base_link (ns "locked") and a
              sphere with a 1 s lifetime (ns "blink"), sent every 2 s
--scan HZ     /scan: 360 rays in base_scan, a wobbly circle of 2 m, intensities
--cloud N     /cloud: N points (x, y, z, rgb) in map, a turning coloured torus, at --cloud-rate
--map         /map: a 10 m x 10 m OccupancyGrid at 5 cm (walls, free space, an unknown corner)
--nav         /plan (Path), /goal_pose (PoseStamped), /particles (PoseArray), /odom
              (Odometry), /footprint (PolygonStamped, base_link)
--bad         /bad_cloud (a PointCloud2 whose data is too short), /bad_scan (in frame
              "nowhere"), /bad_markers (a marker with NaN in its pose beside a good one)
--imarker     an interactive marker server on /simple_marker: "mover" (MOVE_AXIS along x and
              ROTATE_AXIS about z) at (2, -2, 0.5) in map; prints "FEEDBACK <event> <x> <y>
              <yaw>" for each feedback
Always: prints "INITIALPOSE x y yaw frame" and "GOAL x y yaw frame" for what arrives on
/initialpose and /move_base_simple/goal ("SECOND_GOAL x y frame" on
/second/move_base_simple/goal), and "READY" once everything is advertised.
"""

from __future__ import annotations

import argparse
import math
import sys
import threading
import time
from pathlib import Path

import numpy as np

import rospy
from geometry_msgs.msg import (
    Point,
    Point32,
    PolygonStamped,
    Pose,
    PoseArray,
    PoseStamped,
    PoseWithCovarianceStamped,
    TransformStamped,
)
from nav_msgs.msg import OccupancyGrid, Odometry
from nav_msgs.msg import Path as PathMsg
from sensor_msgs.msg import LaserScan, PointCloud2, PointField
from std_msgs.msg import ColorRGBA
from visualization_msgs.msg import Marker, MarkerArray

URDF = Path(__file__).resolve().parent / "scene_pkg" / "urdf" / "robot.urdf"
LINKS = [("base_footprint", "base_link", (0, 0, 0)), ("base_link", "wheel_left", (0, 0.17, 0.06)),
         ("base_link", "wheel_right", (0, -0.17, 0.06)), ("base_link", "caster", (-0.15, 0, 0.03)),
         ("base_link", "base_scan", (0, 0, 0.13)), ("base_link", "bumper", (0.2, 0, 0.03)),
         ("base_link", "antenna", (-0.12, 0.1, 0.25))]


def out(text: str) -> None:
    print(text, flush=True)


def yaw_of(q) -> float:
    return math.atan2(2 * (q.w * q.z + q.x * q.y), 1 - 2 * (q.y * q.y + q.z * q.z))


def transform(parent: str, child: str, xyz, yaw: float = 0.0, stamp=None) -> TransformStamped:
    t = TransformStamped()
    t.header.frame_id, t.child_frame_id = parent, child
    t.header.stamp = stamp or rospy.Time.now()
    t.transform.translation.x, t.transform.translation.y, t.transform.translation.z = xyz
    t.transform.rotation.z, t.transform.rotation.w = math.sin(yaw / 2), math.cos(yaw / 2)
    return t


def robot_pose(now: float):
    """The robot drives a circle of 1 m about (0, 0) in 20 s."""
    angle = 2 * math.pi * now / 20.0
    return math.cos(angle), math.sin(angle), angle + math.pi / 2


def every(period: float, step, stop: threading.Event) -> None:
    next_time = time.monotonic()
    while not stop.is_set() and not rospy.is_shutdown():
        step()
        next_time += period
        delay = next_time - time.monotonic()
        if delay > 0:
            stop.wait(delay)
        elif delay < -0.5:
            next_time = time.monotonic()


def marker(ns: str, mid: int, kind: int, x: float, y: float, z: float = 0.5, frame: str = "map",
           scale=(0.3, 0.3, 0.3), color=(0.2, 0.7, 1.0, 1.0)) -> Marker:
    m = Marker(ns=ns, id=mid, type=kind, action=Marker.ADD)
    m.header.frame_id = frame
    m.pose.position.x, m.pose.position.y, m.pose.position.z = x, y, z
    m.pose.orientation.w = 1.0
    m.scale.x, m.scale.y, m.scale.z = scale
    m.color = ColorRGBA(*color)
    return m


def all_markers() -> MarkerArray:
    names = ["ARROW", "CUBE", "SPHERE", "CYLINDER", "LINE_STRIP", "LINE_LIST", "CUBE_LIST",
             "SPHERE_LIST", "POINTS", "TEXT_VIEW_FACING", "MESH_RESOURCE", "TRIANGLE_LIST"]
    array = MarkerArray()
    ring = [Point(0.25 * math.cos(a), 0.25 * math.sin(a), 0.1 * math.sin(3 * a))
            for a in np.linspace(0, 2 * math.pi, 12)]
    rainbow = [ColorRGBA(abs(math.cos(a)), abs(math.sin(a)), 0.5, 1.0) for a in np.linspace(0, 3, 12)]
    for kind, name in enumerate(names):
        y = -3.0 + kind * 0.6
        m = marker("shapes", kind, kind, 4.0, y)
        if kind == Marker.ARROW:
            m.scale.x, m.scale.y, m.scale.z = 0.5, 0.08, 0.08
        elif kind in (Marker.LINE_STRIP, Marker.LINE_LIST):
            m.scale.x = 0.03
            m.points, m.colors = list(ring), list(rainbow)
        elif kind in (Marker.CUBE_LIST, Marker.SPHERE_LIST, Marker.POINTS):
            m.scale.x = m.scale.y = m.scale.z = 0.08
            m.points, m.colors = list(ring), list(rainbow)
        elif kind == Marker.TEXT_VIEW_FACING:
            m.text, m.scale.z = "hello", 0.2
        elif kind == Marker.MESH_RESOURCE:
            m.mesh_resource = "package://scene_pkg/meshes/pyramid.dae"
            m.mesh_use_embedded_materials = True
            m.scale.x = m.scale.y = m.scale.z = 1.5
        elif kind == Marker.TRIANGLE_LIST:
            m.points = [Point(0, 0, 0), Point(0.3, 0, 0), Point(0, 0.3, 0),
                        Point(0, 0, 0), Point(0, 0.3, 0), Point(-0.3, 0, 0)]
            m.scale.x = m.scale.y = m.scale.z = 1.0
        array.markers.append(m)
        text = marker("labels", kind, Marker.TEXT_VIEW_FACING, 4.5, y, 0.5, scale=(0, 0, 0.12),
                      color=(1, 1, 1, 1))
        text.text = name
        array.markers.append(text)
    locked = marker("locked", 0, Marker.ARROW, 0, 0, 0.3, frame="base_link", scale=(0.4, 0.05, 0.05),
                    color=(1.0, 0.5, 0.0, 1.0))
    locked.frame_locked = True
    blink = marker("blink", 0, Marker.SPHERE, 4.0, 4.2, 0.5, color=(1.0, 1.0, 0.0, 1.0))
    blink.lifetime = rospy.Duration(1.0)
    array.markers += [locked, blink]
    return array


def torus_cloud(count: int, turn: float) -> bytes:
    """``count`` points (x, y, z, rgb float32) on a torus of 1.5 m at (0, 0, 1), turned."""
    rng = np.random.default_rng(1)
    u = rng.uniform(0, 2 * np.pi, count) + turn
    v = rng.uniform(0, 2 * np.pi, count)
    data = np.empty(count, dtype=[("x", "<f4"), ("y", "<f4"), ("z", "<f4"), ("rgb", "<u4")])
    data["x"] = (1.5 + 0.4 * np.cos(v)) * np.cos(u)
    data["y"] = (1.5 + 0.4 * np.cos(v)) * np.sin(u)
    data["z"] = 1.0 + 0.4 * np.sin(v)
    hue = (u % (2 * np.pi)) / (2 * np.pi)
    r = (255 * np.clip(np.abs(hue * 6 - 3) - 1, 0, 1)).astype(np.uint32)
    g = (255 * np.clip(2 - np.abs(hue * 6 - 2), 0, 1)).astype(np.uint32)
    b = (255 * np.clip(2 - np.abs(hue * 6 - 4), 0, 1)).astype(np.uint32)
    data["rgb"] = (r << 16) | (g << 8) | b
    return data.tobytes()


def cloud_msg(count: int, data: bytes) -> PointCloud2:
    msg = PointCloud2(height=1, width=count, is_bigendian=False, point_step=16,
                      row_step=16 * count, is_dense=True, data=data)
    msg.fields = [PointField("x", 0, PointField.FLOAT32, 1), PointField("y", 4, PointField.FLOAT32, 1),
                  PointField("z", 8, PointField.FLOAT32, 1), PointField("rgb", 12, PointField.FLOAT32, 1)]
    msg.header.frame_id = "map"
    return msg


def grid_msg() -> OccupancyGrid:
    grid = OccupancyGrid()
    grid.header.frame_id = "map"
    grid.info.resolution, grid.info.width, grid.info.height = 0.05, 200, 200
    grid.info.origin.position.x = grid.info.origin.position.y = -5.0
    grid.info.origin.orientation.w = 1.0
    cells = np.zeros((200, 200), np.int8)
    cells[:4, :] = cells[-4:, :] = cells[:, :4] = cells[:, -4:] = 100  # walls
    cells[60:64, 40:120] = 100
    cells[150:, 150:] = -1  # unknown corner
    cells[100:110, 20:30] = 50
    grid.data = cells.ravel().tolist()
    return grid


def main() -> None:
    parser = argparse.ArgumentParser()
    for flag in ("--robot", "--markers", "--map", "--nav", "--bad", "--imarker", "--all"):
        parser.add_argument(flag, action="store_true")
    parser.add_argument("--scan", type=float, default=0)
    parser.add_argument("--cloud", type=int, default=0)
    parser.add_argument("--cloud-rate", type=float, default=10.0)
    args = parser.parse_args(rospy.myargv()[1:])
    if args.all:
        args.robot = args.markers = args.map = args.nav = args.bad = args.imarker = True
        args.scan = args.scan or 10.0
    rospy.init_node("scene_sources")
    stop = threading.Event()
    threads = []

    def start(period, step):
        thread = threading.Thread(target=every, args=(period, step, stop), daemon=True)
        threads.append(thread)

    def on_initialpose(msg):
        p = msg.pose.pose
        out(f"INITIALPOSE {p.position.x:.3f} {p.position.y:.3f} {yaw_of(p.orientation):.3f} "
            f"{msg.header.frame_id} {msg.pose.covariance[0]:.4f} {msg.pose.covariance[35]:.5f}")

    def on_goal(msg):
        p = msg.pose
        out(f"GOAL {p.position.x:.3f} {p.position.y:.3f} {yaw_of(p.orientation):.3f} "
            f"{msg.header.frame_id}")
    rospy.Subscriber("/initialpose", PoseWithCovarianceStamped, on_initialpose)
    rospy.Subscriber("/move_base_simple/goal", PoseStamped, on_goal)

    def on_second_goal(msg):
        out(f"SECOND_GOAL {msg.pose.position.x:.3f} {msg.pose.position.y:.3f} {msg.header.frame_id}")
    rospy.Subscriber("/second/move_base_simple/goal", PoseStamped, on_second_goal)

    if args.robot:
        from tf2_msgs.msg import TFMessage
        from tf2_ros import StaticTransformBroadcaster

        rospy.set_param("/robot_description", URDF.read_text())
        # a second robot as minros sim names several: its description and tf_prefix under its
        # namespace, its frames prefixed; it stands still at (-1, 2)
        rospy.set_param("/second/robot_description", URDF.read_text())
        rospy.set_param("/second/tf_prefix", "second")
        static = StaticTransformBroadcaster()
        static.sendTransform([transform("map", "odom", (0, 0, 0))] +
                             [transform(p, c, xyz) for p, c, xyz in LINKS] +
                             [transform("map", "second/base_footprint", (-1, 2, 0))] +
                             [transform("second/" + p, "second/" + c, xyz) for p, c, xyz in LINKS])

        class OldSensor(rospy.SubscribeListener):
            def peer_subscribe(self, topic_name, topic_publish, peer_publish):
                peer_publish(TFMessage([transform("map", "old_sensor", (-2, 2, 0.5))]))
        tf_pub = rospy.Publisher("/tf", TFMessage, queue_size=100, subscriber_listener=OldSensor())

        def send_tf():
            x, y, yaw = robot_pose(time.time())
            tf_pub.publish(TFMessage([transform("odom", "base_footprint", (x, y, 0), yaw)]))
        start(0.05, send_tf)

    if args.markers:
        markers_pub = rospy.Publisher("/markers", MarkerArray, queue_size=10, latch=True)
        markers = all_markers()

        def send_markers():
            for m in markers.markers:
                m.header.stamp = rospy.Time.now() if m.ns != "locked" else rospy.Time()
            markers_pub.publish(markers)
        start(2.0, send_markers)

    if args.scan:
        scan_pub = rospy.Publisher("/scan", LaserScan, queue_size=2)
        angles = np.linspace(0, 2 * math.pi, 360, endpoint=False)

        def send_scan():
            scan = LaserScan(angle_min=0.0, angle_max=2 * math.pi - math.pi / 180,
                             angle_increment=math.pi / 180, range_min=0.12, range_max=3.5,
                             scan_time=1.0 / args.scan)
            scan.header.frame_id, scan.header.stamp = "base_scan", rospy.Time.now()
            scan.ranges = (2.0 + 0.3 * np.sin(5 * angles + time.time())).tolist()
            scan.intensities = (100 * (1 + np.cos(angles))).tolist()
            scan_pub.publish(scan)
        start(1.0 / args.scan, send_scan)

    if args.cloud:
        cloud_pub = rospy.Publisher("/cloud", PointCloud2, queue_size=2)
        clouds = [cloud_msg(args.cloud, torus_cloud(args.cloud, turn)) for turn in np.linspace(0, 0.5, 5)]
        sent = [0]

        def send_cloud():
            msg = clouds[sent[0] % len(clouds)]
            msg.header.stamp = rospy.Time.now()
            cloud_pub.publish(msg)
            sent[0] += 1
        start(1.0 / args.cloud_rate, send_cloud)

    if args.map:
        rospy.Publisher("/map", OccupancyGrid, queue_size=1, latch=True).publish(grid_msg())

    if args.nav:
        path_pub = rospy.Publisher("/plan", PathMsg, queue_size=1, latch=True)
        goal_pub = rospy.Publisher("/goal_pose", PoseStamped, queue_size=1, latch=True)
        particles_pub = rospy.Publisher("/particles", PoseArray, queue_size=1, latch=True)
        odom_pub = rospy.Publisher("/odom", Odometry, queue_size=10)
        footprint_pub = rospy.Publisher("/footprint", PolygonStamped, queue_size=1)
        path = PathMsg()
        path.header.frame_id = "map"
        for i in range(60):
            stamped = PoseStamped()
            stamped.pose.position.x = -1.5 + 0.05 * i
            stamped.pose.position.y = -3.0 + 0.6 * math.sin(i / 8)
            stamped.pose.orientation.w = 1.0
            path.poses.append(stamped)
        path_pub.publish(path)
        goal = PoseStamped()
        goal.header.frame_id = "map"
        goal.pose.position.x, goal.pose.position.y = 1.5, -3.0
        goal.pose.orientation.w = 1.0
        goal_pub.publish(goal)
        particles = PoseArray()
        particles.header.frame_id = "map"
        rng = np.random.default_rng(2)
        for _ in range(50):
            pose = Pose()
            pose.position.x, pose.position.y = rng.normal(-2.5, 0.3), rng.normal(-1.0, 0.3)
            yaw = rng.normal(0.5, 0.3)
            pose.orientation.z, pose.orientation.w = math.sin(yaw / 2), math.cos(yaw / 2)
            particles.poses.append(pose)
        particles_pub.publish(particles)
        footprint = PolygonStamped()
        footprint.header.frame_id = "base_link"
        footprint.polygon.points = [Point32(0.25, 0.2, 0), Point32(-0.25, 0.2, 0),
                                    Point32(-0.25, -0.2, 0), Point32(0.25, -0.2, 0)]

        def send_nav():
            x, y, yaw = robot_pose(time.time())
            odom = Odometry()
            odom.header.frame_id, odom.child_frame_id = "odom", "base_footprint"
            odom.header.stamp = rospy.Time.now()
            odom.pose.pose.position.x, odom.pose.pose.position.y = x, y
            odom.pose.pose.orientation.z, odom.pose.pose.orientation.w = math.sin(yaw / 2), math.cos(yaw / 2)
            odom_pub.publish(odom)
            footprint.header.stamp = rospy.Time.now()
            footprint_pub.publish(footprint)
        start(0.1, send_nav)

    if args.bad:
        bad_cloud = rospy.Publisher("/bad_cloud", PointCloud2, queue_size=1, latch=True)
        msg = cloud_msg(100, torus_cloud(100, 0.0)[:-40])
        bad_cloud.publish(msg)
        bad_scan = rospy.Publisher("/bad_scan", LaserScan, queue_size=1)
        bad_markers = rospy.Publisher("/bad_markers", MarkerArray, queue_size=1, latch=True)
        good = marker("good", 0, Marker.CUBE, -3.0, 3.0, color=(0.3, 1.0, 0.3, 1.0))
        nan = marker("bad", 1, Marker.CUBE, float("nan"), 3.0)
        bad_markers.publish(MarkerArray(markers=[good, nan]))

        def send_bad_scan():
            scan = LaserScan(angle_min=0.0, angle_increment=0.1, range_min=0.1, range_max=5.0,
                             ranges=[1.0] * 30)
            scan.header.frame_id, scan.header.stamp = "nowhere", rospy.Time.now()
            bad_scan.publish(scan)
        start(0.5, send_bad_scan)

    if args.imarker:
        from interactive_markers.interactive_marker_server import InteractiveMarkerServer
        from visualization_msgs.msg import InteractiveMarker, InteractiveMarkerControl

        server = InteractiveMarkerServer("simple_marker")
        im = InteractiveMarker(name="mover", description="drag me", scale=0.8)
        im.header.frame_id = "map"
        im.pose.position.x, im.pose.position.y, im.pose.position.z = 2.0, -2.0, 0.5
        im.pose.orientation.w = 1.0
        body = InteractiveMarkerControl(name="body", always_visible=True,
                                        interaction_mode=InteractiveMarkerControl.NONE)
        box = marker("", 0, Marker.CUBE, 0, 0, 0, frame="", scale=(0.3, 0.3, 0.3), color=(0.5, 0.5, 0.5, 1))
        body.markers.append(box)
        move_x = InteractiveMarkerControl(name="move_x", interaction_mode=InteractiveMarkerControl.MOVE_AXIS)
        move_x.orientation.w = 1.0
        rotate_z = InteractiveMarkerControl(name="rotate_z", interaction_mode=InteractiveMarkerControl.ROTATE_AXIS)
        rotate_z.orientation.w = rotate_z.orientation.y = math.sqrt(0.5)
        im.controls += [body, move_x, rotate_z]

        def on_feedback(feedback):
            p = feedback.pose
            out(f"FEEDBACK {feedback.event_type} {feedback.control_name} {p.position.x:.3f} "
                f"{p.position.y:.3f} {yaw_of(p.orientation):.3f} {feedback.header.frame_id}")
            server.applyChanges()
        server.insert(im, on_feedback)
        server.applyChanges()

    for thread in threads:
        thread.start()
    time.sleep(0.5)
    out("READY")
    try:
        rospy.spin()
    finally:
        stop.set()


if __name__ == "__main__":
    sys.exit(main())
