"""The README's example, end to end in a real browser: ``minros sim --web PORT``, the page's 3D
view, a click-and-drag with "2D Nav Goal", and the simulated robot drives there.

Debian's chromium (software WebGL) driven by Playwright; the robot's position is read from the
view itself (its base_footprint frame in the map frame) and from the simulator's ground truth.
Screenshots as in test_page_3d.py (``MINROS_SCREENSHOTS``).
"""

from __future__ import annotations

import math
import time
import urllib.request

import pytest
from page_support import playwright_api, require_browser, shots_fixture
from test_page_3d import Page, V

from sim_support import READY, Sim
from support import free_port, launch_chromium, wait_until


@pytest.fixture(scope="module")
def sim(tmp_path_factory):
    require_browser()
    home = tmp_path_factory.mktemp("sim3d")
    (home / "log").mkdir()
    web_port = free_port()
    running = Sim(home, "--web", str(web_port), wait_for=("Hz steps", READY))
    running.web_port = web_port

    def web_up() -> bool:
        try:
            with urllib.request.urlopen(f"http://127.0.0.1:{web_port}/", timeout=2) as reply:
                return reply.status == 200
        except OSError:
            return False
    try:
        wait_until(web_up, timeout=30, what="minros web, started by minros sim --web")
        yield running
    finally:
        out = running.stop()
        assert "Traceback" not in out, out[-4000:]


def yaw_of(pose: list) -> float:
    qx, qy, qz, qw = pose[3:]
    return math.atan2(2 * (qw * qz + qx * qy), 1 - 2 * (qy * qy + qz * qz))


shots = shots_fixture()


def test_a_nav_goal_clicked_in_the_3d_view_drives_the_simulated_robot(sim, shots):
    with playwright_api.sync_playwright() as p:
        browser = launch_chromium(p, "--use-angle=swiftshader", "--enable-unsafe-swiftshader")
        page = Page(browser, sim, shots)
        try:
            page.open()
            # what minros sim publishes, each in its display: the robot (URDF), the map, the scan
            for source in ("/robot_description", "/map", "/scan", "/odom"):
                page.wait_status(source, "ok", 30_000)
            page.wait(f"{V}.fixed === 'map' && {V}.scene3d.frames.has('base_scan')")
            start = page.frame("base_footprint")
            assert math.hypot(start[0], start[1]) < 0.05  # the robot starts at the origin
            page.look((1.0, 0.2, 0.0), (-1.2, -2.4, 2.4))
            # the robot's nine frames crowd their names at this distance
            page.js(f"{V}.displays.find((d) => d.kind === 'tf').setOption('names', false)")
            page.shot("view3d_sim_start")
            # Rviz's gesture: press where the robot should go, drag towards where it faces
            page.page.get_by_role("button", name="2D Nav Goal").click()
            page.drag(page.project(1.8, 0.5, 0.0), page.project(1.8, 1.2, 0.0))
            note = page.page.locator(".view3d-note").inner_text()
            assert "2D Nav Goal: published x 1.80, y 0.50, yaw 90°" in note, note
            # move_base plans (the Path display gets it) and the robot drives to the goal
            page.wait("(() => { const p = " + V + ".summary().find((d) => d.source === "
                      "'/move_base/NavfnROS/plan'); return p && p.received > 0; })()", 15_000)
            page.wait(f"(() => {{ const f = {V}.scene3d.frames.get('base_footprint'); "
                      "return f && f.T && Math.hypot(f.T[0] - 0.9, f.T[1] - 0.25) < 0.3; })()", 30_000)
            page.shot("view3d_sim_driving")
            # until it stops: move_base's tolerances are 0.08 m and 0.17 rad
            deadline = time.monotonic() + 60
            last = None
            while time.monotonic() < deadline:
                time.sleep(1.0)
                pose = page.frame("base_footprint")
                if last and math.hypot(pose[0] - last[0], pose[1] - last[1]) < 0.003 and \
                        abs(math.remainder(yaw_of(pose) - yaw_of(last), 2 * math.pi)) < 0.005:
                    break
                last = pose
            assert math.hypot(pose[0] - 1.8, pose[1] - 0.5) < 0.1, pose
            assert abs(math.remainder(yaw_of(pose) - math.pi / 2, 2 * math.pi)) < 0.2, pose
            x, y = sim.ground_truth()
            assert math.hypot(x - pose[0], y - pose[1]) < 0.02  # the view shows where it is
            page.shot("view3d_sim_arrived")
        finally:
            page.close()
            browser.close()
