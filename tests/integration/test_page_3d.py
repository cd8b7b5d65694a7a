"""The page's 3D view in a real browser: Debian's chromium (software WebGL) driven by Playwright.

One running system for the module: minros core, tests/web/scene_sources.py publishing what Rviz
shows (tf and a URDF robot with STL/COLLADA/OBJ meshes from tests/web/scene_pkg, markers of
every type, a scan, a map, a path, poses, odometry, a polygon, an interactive marker server,
and broken data: a short cloud, a scan in an unknown frame, a marker with NaN) and minros web.
Each test drives the view as a user would, checks what is drawn (the scene's objects, pixels
read back from WebGL, the statuses in the display list) and saves a screenshot
(``$MINROS_SCREENSHOTS``, else a temporary folder; the README's are made with
``MINROS_SCREENSHOTS=docs/screenshots``).

The performance test publishes a PointCloud2 of 100,000 points at 10 Hz and measures, in the
page, the frames drawn and the clouds taken per second, with the camera still and then turning,
for ``MINROS_3D_SECONDS`` (20 by default, half each), with the cloud display's "max points" at
``MINROS_3D_MAX_POINTS`` if set (0: all; else the page's default); it prints them and writes
view3d_perf.json beside the screenshots.
"""

from __future__ import annotations

import json
import math
import os
import time
import xmlrpc.client
from pathlib import Path

import page_support
import pytest
from page_support import browser_fixture, playwright_api, shots_fixture, system_fixture

from support import PYTHON, REFERENCE_PYTHON, require_reference

WEB = Path(__file__).resolve().parent.parent / "web"
PERF_SECONDS = float(os.environ.get("MINROS_3D_SECONDS", "20"))
PERF_MAX_POINTS = os.environ.get("MINROS_3D_MAX_POINTS")
V = "minrosPage.view('3d')"


class System(page_support.System):
    """minros core, what Rviz would show (scene_sources.py --all), and minros web."""

    def __init__(self, tmp: Path) -> None:
        super().__init__(tmp, {"ROS_PACKAGE_PATH": str(WEB)})

    def up(self) -> None:
        self.start_core()
        self.sources = self.start([PYTHON, str(WEB / "scene_sources.py"), "--all"])
        self.sources.read_until("READY", timeout=30)
        self.start_web()


system = system_fixture(System, "page3d")
# software WebGL (SwiftShader) on a machine without a GPU
browser = browser_fixture("--use-angle=swiftshader", "--enable-unsafe-swiftshader")
shots = shots_fixture()


class Page(page_support.Page):
    """One tab on the 3D view, its console errors collected."""

    MIN_SHOT_BYTES = 20_000

    def open(self) -> None:
        self.page.goto(f"http://127.0.0.1:{self.system.web_port}/#3d")
        self.page.wait_for_function("window.minrosPage && minrosPage.conn.state === 'connected' "
                                    f"&& {V}.ready && {V}.scene3d.frames.size > 5", timeout=30_000)

    def displays(self) -> dict:
        return {d["source"] or d["kind"]: d for d in self.js(f"{V}.summary()")}

    def wait_status(self, source: str, level: str, timeout: float = 20_000) -> dict:
        self.wait(f"{V}.summary().some((d) => (d.source || d.kind) === {json.dumps(source)} "
                  f"&& d.level === {json.dumps(level)})", timeout)
        return self.displays()[source]

    def project(self, x: float, y: float, z: float) -> tuple:
        point = self.js(f"{V}.scene3d.project({x}, {y}, {z})")
        assert point["inside"], (x, y, z, point)
        return point["x"], point["y"]

    def pixel(self, x: float, y: float, z: float) -> list:
        px, py = self.project(x, y, z)
        return self.js(f"{V}.scene3d.pixel({px}, {py})")

    def wait_pixel(self, point: tuple, condition: str, timeout: float = 5_000) -> None:
        """Wait until the colour drawn at ``point`` (of the fixed frame) meets ``condition``, a JS
        expression of r, g, b (the scene may still be taking the last tf in)."""
        px, py = self.project(*point)
        try:
            self.wait(f"(([r, g, b]) => {condition})({V}.scene3d.pixel({px}, {py}))", timeout)
        except playwright_api.TimeoutError:
            raise AssertionError(f"the colour at {point} is {self.pixel(*point)}, not {condition}") from None

    def look(self, target, eye) -> None:
        self.js(f"{V}.scene3d.lookAt({json.dumps(list(target))}, {json.dumps(list(eye))})")

    def frame(self, name: str) -> list:
        return self.js(f"({V}.scene3d.frames.get({json.dumps(name)}) || {{}}).T || null")

    def drag(self, start: tuple, end: tuple, steps: int = 12) -> None:
        mouse = self.page.mouse
        mouse.move(*start)
        mouse.down()
        mouse.move(*end, steps=steps)
        mouse.up()


@pytest.fixture
def page(browser, system, shots):
    tab = Page(browser, system, shots)
    try:
        tab.open()
        yield tab
    finally:
        tab.close()


def in_frame(T: list, point: tuple) -> tuple:
    """``point`` of a frame whose pose is ``T`` (x, y, z, qx, qy, qz, qw), in the fixed frame."""
    x, y, z, qx, qy, qz, qw = T
    px, py, pz = point
    # v + 2 w (q x v) + 2 q x (q x v)
    cx, cy, cz = qy * pz - qz * py, qz * px - qx * pz, qx * py - qy * px
    dx, dy, dz = qy * cz - qz * cy, qz * cx - qx * cz, qx * cy - qy * cx
    return (x + px + 2 * (qw * cx + dx), y + py + 2 * (qw * cy + dy), z + pz + 2 * (qw * cz + dz))


def sources_line(system: System, prefix: str, timeout: float = 15) -> list:
    """The fields of the next line the sources print that starts with ``prefix``."""
    text = system.sources.read_until(prefix + " ", timeout=timeout)
    line = [ln for ln in text.splitlines() if ln.startswith(prefix + " ")][-1]
    return line.split()[1:]


# -- every display, and what is broken says so -----------------------------------------------------

def test_every_display_draws_and_bad_ones_say_why(page):
    for source in ("/markers", "/scan", "/map", "/plan", "/goal_pose", "/particles", "/odom",
                   "/footprint", "/simple_marker/update", "/robot_description"):
        page.wait_status(source, "ok")
    shown = page.displays()
    assert shown["/scan"]["count"] == 360 and shown["/markers"]["markers"] >= 24
    assert shown["grid3d"]["level"] == "ok"
    # old_sensor is sent once: TF warns about it once it is 5 s old, and about nothing else
    assert shown["tf"]["level"] == "ok" or shown["tf"]["text"].endswith(": old_sensor"), shown["tf"]
    # broken data: its display says what is wrong, the rest goes on
    cloud = page.wait_status("/bad_cloud", "error")
    assert "PointCloud2 data holds 1560 bytes" in cloud["text"] and cloud["received"] == 0
    scan = page.wait_status("/bad_scan", "error")
    assert scan["text"].startswith("No transform from [nowhere] to [map]")
    bad = page.wait_status("/bad_markers", "warn")
    assert "marker bad/1: the message contains NaN" in bad["text"] and bad["markers"] == 1
    status = page.page.locator('.display-row[data-kind="scan"][data-level="error"] .display-status')
    assert "nowhere" in status.inner_text()
    # drawn: the light blue CUBE marker, the map's unknown corner (Rviz's grey green)
    page.look((0.5, -0.5, 0), (4.5, -6.5, 5))
    # a point projected in the same task as the camera moved (no frame drawn between) is where
    # the next frame draws it
    moved = page.js(f"{V}.scene3d.resetCamera() || {V}.scene3d.lookAt([0.5, -0.5, 0], [4.5, -6.5, 5]) "
                    f"|| {V}.scene3d.project(4.0, -2.4, 0.5)")
    assert moved["inside"] and (moved["x"], moved["y"]) == pytest.approx(page.project(4.0, -2.4, 0.5)), moved
    # marker "shapes"/1, a CUBE of (0.2, 0.7, 1.0); map cells [150:, 150:] are unknown (-1)
    page.wait_pixel((4.0, -2.4, 0.5), "b > 180 && g > 110 && r < 110")
    page.wait_pixel((3.5, 3.5, 0.0), "g > r + 10 && Math.abs(g - b) < 25 && g > 90 && g < 190")
    rendered = page.js(f"{V}.scene3d.stats.rendered")
    page.wait(f"{V}.scene3d.stats.rendered > {rendered} + 5")  # the scan and tf keep it drawing
    page.shot("view3d_overview")


def test_the_robot_model_has_every_geometry_and_mesh(page):
    robot = page.wait_status("/robot_description", "ok")
    assert robot["received"] == 1
    first = f"{V}.displays.find((d) => d.source === '/robot_description')"
    page.wait(f"{first}.meshes.pending === 0 && {first}.meshes.loaded.size === 3")
    info = page.js(f"""(() => {{
      const robot = {first};
      const links = {{}};
      for (const [name, anchor] of robot.links) {{
        let meshes = 0;
        anchor.traverse((o) => {{ if (o.isMesh) meshes++; }});
        links[name] = {{visible: anchor.visible, meshes}};
      }}
      return {{links, errors: [...robot.meshes.errors]}};
    }})()""")
    assert info["errors"] == []
    assert set(info["links"]) == {"base_footprint", "base_link", "wheel_left", "wheel_right",
                                  "caster", "base_scan", "bumper", "antenna"}
    assert all(link["visible"] for link in info["links"].values())
    for name in ("base_link", "wheel_left", "wheel_right", "caster", "base_scan", "bumper", "antenna"):
        assert info["links"][name]["meshes"] >= 1, name
    # follow the robot in its own frame: the DAE pyramid keeps its embedded red, the STL bumper
    # takes the URDF's yellow, the OBJ antenna its green (TF's axes hidden, not to hide them)
    page.js(f"{V}.setEnabled({V}.displays.find((d) => d.kind === 'tf'), false)")
    page.js(f"{V}.setFixed('base_footprint')")
    page.wait(f"{V}.scene3d.fixed === 'base_footprint'")
    page.look((0, 0, 0.15), (0.6, 1.2, 0.8))
    # the side of the box of base_link, URDF blue
    page.wait_pixel((0.12, 0.15, 0.09), "b > r + 60 && b > g + 40")
    page.wait_pixel((0, 0, 0.2), "r > g + 60 && r > b + 60")  # the pyramid on base_scan
    page.wait_pixel((0.25, 0, 0.05), "r > 150 && g > 120 && b < 90")  # the wedge on bumper
    page.wait_pixel((-0.12, 0.1, 0.25), "g > r + 50 && g > b + 30")  # the octahedron on antenna
    page.js(f"{V}.setEnabled({V}.displays.find((d) => d.kind === 'tf'), true)")
    page.shot("view3d_robot")
    page.js(f"{V}.setFixed('map')")
    # the second robot: its description under its namespace, its frames under its tf_prefix
    second = page.wait_status("/second/robot_description", "ok")
    assert second["received"] >= 1
    page.wait(f"[...{V}.displays.find((d) => d.source === '/second/robot_description').links.values()]"
              ".every((anchor) => anchor.visible)")
    assert page.js(f"{V}.displays.find((d) => d.source === '/second/robot_description').options.prefix") == "second"
    # matrixWorld follows the new fixed frame at the next render: wait for it, then read it
    where = (f"{V}.displays.find((d) => d.source === '/second/robot_description')"
             ".links.get('base_footprint').matrixWorld.elements.slice(12, 14)")
    try:
        page.wait(f"((e) => Math.abs(e[0] + 1) < 1e-6 && Math.abs(e[1] - 2) < 1e-6)({where})", 10_000)
    except Exception:  # the assertion below says where it is instead
        pass
    base = page.js(where)
    assert base == pytest.approx([-1.0, 2.0], abs=1e-6)
    # a new description is drawn when the parameter changes; a broken one says why
    master = xmlrpc.client.ServerProxy(f"http://127.0.0.1:{page.system.port}/")
    master.setParam("/test", "/second/robot_description",
                    '<robot name="r"><link name="base_footprint"><visual><geometry>'
                    '<sphere radius="0.3"/></geometry></visual></link></robot>')
    page.wait(f"{V}.displays.find((d) => d.source === '/second/robot_description').links.size === 1")
    master.setParam("/test", "/second/robot_description", "<robot><link")
    broken = page.wait_status("/second/robot_description", "error")
    assert broken["text"].startswith("the robot description is not valid XML")


def test_markers_namespaces_and_lifetimes(page):
    page.wait_status("/markers", "ok")
    names = page.js(f"[...{V}.displays.find((d) => d.source === '/markers').namespaces.keys()].sort()")
    assert names == ["blink", "labels", "locked", "shapes"]
    blink = f"{V}.displays.find((d) => d.source === '/markers').markers.has('blink\\u0000' + 0)"
    page.wait(blink, 10_000)  # sent every 2 s with a lifetime of 1 s: it comes and goes
    page.wait("!" + blink, 3_000)
    page.wait(blink, 5_000)
    texts = page.js(f"""(() => {{
      const out = [];
      {V}.displays.find((d) => d.source === '/markers').group.traverse((o) => {{
        if (o.userData.text) out.push(o.userData.text); }});
      return out.sort();
    }})()""")
    assert "hello" in texts and "MESH_RESOURCE" in texts and "TRIANGLE_LIST" in texts
    row = page.page.locator('.display-row[data-kind="markers"]').filter(has_text="/markers")
    row.locator("summary").click()
    row.get_by_label("labels").uncheck()
    assert page.js(f"{V}.displays.find((d) => d.source === '/markers').namespaces.get('labels').group.visible") is False
    row.get_by_label("labels").check()


def test_tf_frames_fade_when_stale_and_the_fixed_frame_changes(page):
    page.wait(f"({V}.scene3d.frames.get('old_sensor') || {{}}).stale === true", 15_000)
    read = f"""(() => {{
      const tf = {V}.displays.find((d) => d.kind === 'tf');
      let found = null;
      tf.items.get('old_sensor').group.traverse((o) => {{ if (o.material && found === null) found = o.material.opacity; }});
      return found;
    }})()"""
    # the TF display fades a frame at its next tick after the scene marks it stale
    try:
        page.wait(f"Math.abs({read} - 0.25) < 1e-6", 10_000)
    except Exception:  # the assertion below says what it is instead
        pass
    assert page.js(read) == pytest.approx(0.25)
    tf = page.displays()["tf"]
    assert tf["level"] == "warn" and "old_sensor" in tf["text"]
    # a fixed frame tf does not know: said in the global options, nothing breaks
    page.page.locator(".view3d-fixed").fill("no_such_frame")
    page.page.locator(".view3d-fixed").press("Enter")
    page.wait("document.querySelector('.view3d-fixed-status').textContent === "
              "'Fixed Frame [no_such_frame] does not exist'")
    page.wait(f"!{V}.displays.find((d) => d.kind === 'robot').links.get('base_link').visible")
    page.page.locator(".view3d-fixed").fill("base_link")
    page.page.locator(".view3d-fixed").press("Enter")
    page.wait(f"{V}.scene3d.fixed === 'base_link' && "
              f"{V}.displays.find((d) => d.kind === 'robot').links.get('base_link').visible")
    assert page.frame("base_link") == [0, 0, 0, 0, 0, 0, 1]
    odom = page.frame("odom")
    assert odom is not None and math.hypot(odom[0], odom[1]) == pytest.approx(1.0, abs=0.05)
    page.js(f"{V}.setFixed('map')")


def test_nav_goal_and_pose_estimate_publish_where_the_mouse_says(page, system):
    page.look((0, 0, 0), (0.01, -6, 8))
    page.page.get_by_role("button", name="2D Nav Goal").click()
    page.drag(page.project(1.0, 1.0, 0.0), page.project(2.0, 1.0, 0.0))
    x, y, yaw, frame = sources_line(system, "GOAL")
    assert (float(x), float(y), float(yaw), frame) == (pytest.approx(1.0, abs=0.03),
                                                       pytest.approx(1.0, abs=0.03),
                                                       pytest.approx(0.0, abs=0.05), "map")
    assert page.js(f"{V}.tool") == "interact"  # one use, as in Rviz
    page.page.get_by_role("button", name="2D Pose Estimate").click()
    page.drag(page.project(-1.0, -1.0, 0.0), page.project(-1.0, 0.0, 0.0))
    x, y, yaw, frame, cov_x, cov_yaw = sources_line(system, "INITIALPOSE")
    assert float(x) == pytest.approx(-1.0, abs=0.03) and float(y) == pytest.approx(-1.0, abs=0.03)
    assert float(yaw) == pytest.approx(math.pi / 2, abs=0.05) and frame == "map"
    assert float(cov_x) == pytest.approx(0.25) and float(cov_yaw) == pytest.approx((math.pi / 12) ** 2, abs=1e-4)
    assert "2D Pose Estimate: published" in page.page.locator(".view3d-note").inner_text()
    page.shot("view3d_tools")
    # a robot under a namespace has its own goal topic: the tool's topic is chosen in the panel
    topic = page.page.get_by_label("2D Nav Goal topic")
    topic.fill("/second/move_base_simple/goal")
    topic.press("Enter")
    page.page.get_by_role("button", name="2D Nav Goal").click()
    page.drag(page.project(-2.0, 1.5, 0.0), page.project(-2.0, 2.5, 0.0))
    x, y, frame = sources_line(system, "SECOND_GOAL")
    assert (float(x), float(y), frame) == (pytest.approx(-2.0, abs=0.03), pytest.approx(1.5, abs=0.03), "map")


def test_an_interactive_marker_is_dragged_and_the_server_moves_it(page, system):
    page.wait_status("/simple_marker/update", "ok")
    page.look((2.5, -2, 0.5), (2.5, -5.5, 3.0))
    pose = page.js(f"{V}.displays.find((d) => d.kind === 'imarkers').worldPose('mover')")
    assert pose[:3] == pytest.approx([2.0, -2.0, 0.5], abs=1e-6)
    # MOVE_AXIS: the +x cone sits 0.7 x scale (0.8) from the marker; drag it 1 m along x
    page.drag(page.project(2.56, -2.0, 0.5), page.project(3.56, -2.0, 0.5))
    events = []
    while True:
        event, control, x, y, yaw, frame = sources_line(system, "FEEDBACK")
        events.append(int(event))
        if int(event) == 5:  # MOUSE_UP
            break
    assert events[0] == 4 and 1 in events and control == "move_x" and frame == "map"
    assert float(x) == pytest.approx(3.0, abs=0.06) and float(y) == pytest.approx(-2.0, abs=1e-3)
    page.wait(f"Math.abs({V}.displays.find((d) => d.kind === 'imarkers').worldPose('mover')[0] - {x}) < 1e-3 "
              f"&& {V}.displays.find((d) => d.kind === 'imarkers').dragging === null")
    # ROTATE_AXIS about z: a quarter turn along the ring (radius 0.6 x 0.8)
    cx = float(x)
    start = page.project(cx, -2.0 + 0.48, 0.5)
    end = page.project(cx - 0.48, -2.0, 0.5)
    page.drag(start, end, steps=16)
    while True:
        event, control, x, y, yaw, frame = sources_line(system, "FEEDBACK")
        if int(event) == 5:
            break
    assert control == "rotate_z" and float(yaw) == pytest.approx(math.pi / 2, abs=0.12)
    assert float(x) == pytest.approx(cx, abs=1e-3)
    page.shot("view3d_interactive")


DEBIAN_SERVER = r"""
import rospy
from interactive_markers.interactive_marker_server import InteractiveMarkerServer
from visualization_msgs.msg import InteractiveMarker, InteractiveMarkerControl

rospy.init_node("debian_im")
server = InteractiveMarkerServer("debian_im")
marker = InteractiveMarker(name="slider", scale=1.0)
marker.header.frame_id = "map"
marker.pose.position.x, marker.pose.position.y, marker.pose.position.z = -3.0, -3.0, 0.5
marker.pose.orientation.w = 1.0
control = InteractiveMarkerControl(name="slide_x", interaction_mode=InteractiveMarkerControl.MOVE_AXIS)
control.orientation.w = 1.0  # no markers: the client draws its own arrows, as Rviz does
marker.controls.append(control)

def on_feedback(fb):
    print("FEEDBACK %d %s %.3f %.3f %s" % (fb.event_type, fb.control_name, fb.pose.position.x,
                                          fb.pose.position.y, fb.header.frame_id), flush=True)
    server.applyChanges()

server.insert(marker, on_feedback)
server.applyChanges()
print("READY", flush=True)
rospy.spin()
"""


@pytest.mark.interop
def test_an_interactive_marker_of_debians_server_is_dragged(page, system):
    """The page drives the interactive_markers server of Debian's ROS (python3-interactive-
    markers, rospy) as Rviz does: its arrows drawn by the client, the drag's feedback to it."""
    require_reference()
    server = system.start([REFERENCE_PYTHON, "-c", DEBIAN_SERVER], reference=True)
    try:
        server.read_until("READY", timeout=30)
        page.wait_status("/debian_im/update", "ok", 30_000)
        page.look((-2.5, -3, 0.5), (-2.5, -6.5, 3.0))
        page.wait(f"{V}.displays.find((d) => d.source === '/debian_im/update').markers.has('slider')")
        page.drag(page.project(-2.3, -3.0, 0.5), page.project(-1.3, -3.0, 0.5))
        while True:
            line = server.read_until("FEEDBACK", timeout=15)
            fields = [ln for ln in line.splitlines() if ln.startswith("FEEDBACK")][-1].split()[1:]
            if int(fields[0]) == 5:  # MOUSE_UP
                break
        assert fields[1] == "slide_x" and fields[4] == "map"
        assert float(fields[2]) == pytest.approx(-2.0, abs=0.06) and float(fields[3]) == pytest.approx(-3.0, abs=1e-3)
    finally:
        out = server.stop()
    assert "Traceback" not in out, out


# -- 100,000 points at 10 Hz -------------------------------------------------------------------------

def measure(page, seconds: float) -> dict:
    """Frames drawn and clouds taken per second over ``seconds``, read in the page."""
    read = (f"[performance.now(), {V}.scene3d.stats.rendered, "
            f"{V}.displays.find((d) => d.source === '/cloud').received]")
    start = page.js(read)
    time.sleep(seconds)
    end = page.js(read)
    elapsed = (end[0] - start[0]) / 1000
    return {"frames_per_second": round((end[1] - start[1]) / elapsed, 1),
            "clouds_per_second": round((end[2] - start[2]) / elapsed, 1)}


def test_a_100k_point_cloud_at_10_hz_frames_per_second(page, system, shots):
    cloud = system.start([PYTHON, str(WEB / "scene_sources.py"), "--cloud", "100000",
                          "--cloud-rate", "10", "__name:=cloud_source"])
    try:
        cloud.read_until("READY", timeout=30)
        page.wait(f"{V}.summary().some((d) => d.source === '/cloud' && d.total === 100000)", 30_000)
        if PERF_MAX_POINTS is not None:
            cloud_display = f"{V}.displays.find((d) => d.source === '/cloud')"
            page.js(f"{cloud_display}.setOption('max_points', {int(PERF_MAX_POINTS)})")
            page.wait(f"{cloud_display}.count === {int(PERF_MAX_POINTS) or 100_000}", 30_000)
        page.js(f"{V}.scene3d.resetCamera()")
        # the camera still: the view draws when something changes (each cloud, tf)
        still = measure(page, PERF_SECONDS / 2)
        # the camera turning: the view draws every frame it can
        page.js(f"{V}.scene3d.controls.autoRotate = true; {V}.scene3d.continuous = true")
        page.js(f"{V}.scene3d.beforeRender.add(() => {V}.scene3d.controls.update())")
        turning = measure(page, PERF_SECONDS / 2)
        page.js(f"{V}.scene3d.controls.autoRotate = false; {V}.scene3d.continuous = false")
        stats = page.js(f"{V}.scene3d.stats")
        count = page.js(f"{V}.displays.find((d) => d.source === '/cloud').count")
        # an option changed on a colored cloud keeps its points' own colors (the flat color
        # used to multiply them: a rainbow turned red and black)
        cloud_display = f"{V}.displays.find((d) => d.source === '/cloud')"
        page.js(f"{cloud_display}.setOption('size', 0.03)")
        colors = page.js(f"[{cloud_display}.material.vertexColors, "
                         f"{cloud_display}.material.color.getHex()]")
        report = {"points": count, "camera_still": still, "camera_turning": turning,
                  "canvas": f"{stats['width']}x{stats['height']}", "renderer": stats["renderer"],
                  "cpus": os.cpu_count(), "load_average": round(os.getloadavg()[0], 1)}
        print("\n3D view, 100k-point PointCloud2 at 10 Hz:", json.dumps(report))
        (shots / "view3d_perf.json").write_text(json.dumps(report, indent=1) + "\n")
        page.shot("view3d_cloud")
    finally:
        cloud.stop()
    assert colors == [True, 0xFFFFFF], colors
    assert count == page.js(f"{V}.displays.find((d) => d.source === '/cloud').request.max_points") or count == 100_000
    # the view keeps drawing and keeps taking clouds, whatever else the machine runs (the
    # server drops what the page cannot take): floors a broken pipeline misses, not a benchmark
    for phase in (still, turning):
        assert phase["frames_per_second"] >= 1.0 and phase["clouds_per_second"] >= 0.3, report
