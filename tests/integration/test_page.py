"""The web page of ``minros web`` in a real browser: Debian's chromium driven by Playwright.

One running system for the module (minros core, turtlesim, talker and listener, a
dynamic_reconfigure server, a test node publishing an image, a cv2.imshow window and log lines
at every level, and minros web), one browser; each test drives a view as a user would and
saves a screenshot. Screenshots go to ``$MINROS_SCREENSHOTS`` when set (the README's pictures
are made with ``MINROS_SCREENSHOTS=docs/screenshots``), else to a temporary folder.

The performance test (a 1 kHz topic plotted beside a 30 Hz VGA picture: frame rate and memory
measured in the page) runs ``MINROS_PAGE_SOAK`` seconds, 20 by default; the issue's 5 minutes
are ``MINROS_PAGE_SOAK=300``.
"""

from __future__ import annotations

import json
import os
import shutil
import time

import page_support
import pytest
from page_support import Page, browser_fixture, shots_fixture, system_fixture

from support import PYTHON, REPO, free_port, wait_until

WEB = REPO / "tests" / "web"
TUTORIALS = REPO / "tests" / "examples" / "library_tutorials"
SOAK_SECONDS = float(os.environ.get("MINROS_PAGE_SOAK", "20"))


class System(page_support.System):
    """The ROS side every test of this module looks at."""

    def up(self) -> None:
        workspace = self.tmp / "ws" / "dynamic_tutorials"
        workspace.mkdir(parents=True)
        shutil.copytree(TUTORIALS / "dynamic_tutorials" / "cfg", workspace / "cfg")
        (workspace / "package.xml").write_text(
            '<?xml version="1.0"?><package format="2"><name>dynamic_tutorials</name>'
            "<version>0.0.0</version><description>page test</description>"
            '<maintainer email="test@example.com">test</maintainer><license>BSD</license>'
            "<buildtool_depend>catkin</buildtool_depend></package>")
        self.start_core()
        self.start([PYTHON, "-m", "minros", "run", "turtlesim", "turtlesim_node"],
                   {"MINROS_HEADLESS": "1"}).read_until("Spawning turtle [turtle1]", timeout=30)
        self.start([PYTHON, "-m", "minros", "run", "rospy_tutorials", "talker"])
        self.start([PYTHON, "-m", "minros", "run", "rospy_tutorials", "listener"])
        self.start([PYTHON, str(TUTORIALS / "dynamic_tutorials" / "nodes" / "server.py")],
                   {"ROS_PACKAGE_PATH": str(self.tmp / "ws")}).read_until("Reconfigure Request", timeout=30)
        self.start([PYTHON, str(WEB / "page_sources.py"), "--image", "10", "--imshow", "--logs"]
                   ).read_until("READY", timeout=30)
        self.start_web()

    def param(self, name: str):
        code, msg, value = self.master.getParam("/page_test", name)
        assert code == 1, msg
        return value


system = system_fixture(System, "page")
browser = browser_fixture("--enable-precise-memory-info")
shots = shots_fixture()


@pytest.fixture
def page(browser, system, shots):
    tab = Page(browser, system, shots)
    try:
        yield tab
    finally:
        tab.close()


# -- graph -------------------------------------------------------------------------------------

@pytest.mark.smoke
def test_graph_shows_the_running_nodes_and_their_info(page):
    page.open("graph")
    graph = page.view("graph")
    talker = graph.locator('.vertex[data-id^="n:/talker"]')
    listener = graph.locator('.vertex[data-id^="n:/listener"]')
    for vertex in (graph.locator('.vertex[data-id="n:/turtlesim"]'), talker, listener,
                   graph.locator('.vertex[data-id="t:/chatter"]'),
                   graph.locator('.vertex[data-id="s:/spawn"]')):
        vertex.wait_for(timeout=10_000)
    # rqt_graph's "Hide Debug": rosout, this server's own node and the logger services
    for hidden in ("n:/rosout", "n:/minros_web", "t:/rosout", "s:/turtlesim/get_loggers"):
        assert graph.locator(f'.vertex[data-id="{hidden}"]').count() == 0, hidden
    assert page.js("minrosPage.graph.mode") == "push"  # minros's master pushes graph changes
    graph.locator('.vertex[data-id="t:/chatter"]').click()
    info = graph.locator(".graph-info")
    info.get_by_text("std_msgs/String").wait_for()
    page.page.wait_for_function(
        "document.querySelector('.graph-info').textContent.match(/Rate(\\d+\\.\\d+) Hz/)", timeout=10_000)
    rate = float(page.js("document.querySelector('.graph-info').textContent.match(/Rate(\\d+\\.\\d+) Hz/)[1]"))
    assert 7 < rate < 13  # the talker says hello at 10 Hz
    graph.locator('.vertex[data-id="n:/turtlesim"]').click()
    info.get_by_text("Pid").wait_for()
    text = info.inner_text()
    assert "/turtle1/pose" in text and "turtlesim/Pose" in text and "/spawn" in text
    assert "/turtle1/cmd_vel" in text  # subscriptions
    page.shot("graph")
    graph.locator("text=debug").click()
    graph.locator('.vertex[data-id="n:/rosout"]').wait_for()


def test_graph_is_pushed_when_a_node_starts(page, system):
    page.open("graph")
    graph = page.view("graph")
    graph.locator('.vertex[data-id="n:/turtlesim"]').wait_for()
    version = page.js("minrosPage.graph.version")
    pub = system.start([PYTHON, "-m", "minros", "topic", "pub", "-r", "1", "/late_topic",
                        "std_msgs/String", "data: late"])
    try:
        graph.locator('.vertex[data-id="t:/late_topic"]').wait_for(timeout=15_000)
        assert page.js("minrosPage.graph.version") > version
    finally:
        pub.stop()
    graph.locator('.vertex[data-id="t:/late_topic"]').wait_for(state="detached", timeout=15_000)


def fleet_registrations() -> list:
    """A fleet of 5 robots with 10 nodes each (drivers, perception, localization, planning,
    control, supervision), plus a fleet manager: (method, node, topic, type) for the master."""
    calls = [("registerPublisher", "/fleet_manager", "/fleet/goals", "geometry_msgs/PoseStamped"),
             ("registerSubscriber", "/fleet_manager", "/fleet/status", "std_msgs/String")]
    for r in range(5):
        ns = f"/robot_{r}"
        wiring = {
            "camera_driver": (["image_raw"], []),
            "lidar_driver": (["scan"], []),
            "imu_driver": (["imu"], []),
            "detector": (["detections"], ["image_raw"]),
            "localization": (["pose"], ["scan", "imu", "odom"]),
            "tracker": (["tracks"], ["detections", "pose"]),
            "planner": (["cmd_vel", "path"], ["tracks", "pose", "/fleet/goals"]),
            "base_controller": (["odom"], ["cmd_vel"]),
            "supervisor": (["/fleet/status"], ["pose", "tracks"]),
            "recorder": ([], ["image_raw", "scan", "path"]),
        }
        for node, (pubs, subs) in wiring.items():
            for method, topics in (("registerPublisher", pubs), ("registerSubscriber", subs)):
                for topic in topics:
                    name = topic if topic.startswith("/") else f"{ns}/{topic}"
                    calls.append((method, f"{ns}/{node}", name, "std_msgs/Header"))
    return calls


def test_graph_of_50_nodes_is_laid_out_readably(browser, system, shots):
    """A fleet of 51 nodes on 37 topics (registered by hand with the master): every node drawn,
    no two boxes overlapping, at a zoom where the labels can be read."""
    fake_api = "http://127.0.0.1:9/"  # nothing listens: the master's callbacks fail fast
    calls = fleet_registrations()
    for method, caller, topic, type_name in calls:
        getattr(system.master, method)(caller, topic, type_name, fake_api)
    tab = Page(browser, system, shots, width=1920, height=1080)
    try:
        tab.open("graph")
        graph = tab.view("graph")
        graph.locator('.vertex[data-id="n:/robot_4/recorder"]').wait_for(timeout=15_000)
        tab.page.wait_for_function("minrosPage.graph.nodes.filter((n) => n.startsWith('/robot_')).length === 50")
        graph.locator("button", has_text="Fit").click()
        boxes = tab.js("""[...document.querySelectorAll('.view-graph .vertex')].map((v) => {
            const r = v.getBoundingClientRect(); return [v.dataset.id, r.left, r.top, r.right, r.bottom]; })""")
        assert sum(1 for b in boxes if b[0].startswith("n:/robot_")) == 50
        for i, a in enumerate(boxes):
            for b in boxes[i + 1:]:
                overlap = a[1] < b[3] - 0.5 and b[1] < a[3] - 0.5 and a[2] < b[4] - 0.5 and b[2] < a[4] - 0.5
                assert not overlap, (a, b)
        tab.shot("graph_50_nodes")
        scale = tab.js("document.querySelector('.view-graph .world').transform.baseVal[1].matrix.a")
        assert scale >= 0.5, f"the whole graph fits only at zoom {scale:.2f}"  # 12 px labels: 6 px or more
    finally:
        tab.close()
        for method, caller, topic, _type in calls:
            getattr(system.master, method.replace("register", "unregister"))(caller, topic, fake_api)


# -- topics, plot, teleop ------------------------------------------------------------------------

def test_topics_view_lists_rates_and_echoes_a_message(page):
    page.open("topics")
    view = page.view("topics")
    row = view.locator('tr[data-topic="/chatter"]')
    row.wait_for()
    page.page.wait_for_function(
        "(() => { const r = document.querySelector('tr[data-topic=\"/turtle1/pose\"]');"
        " return r && parseFloat(r.children[4].textContent) > 30; })()", timeout=15_000)
    view.locator('tr[data-topic="/turtle1/pose"]').click()
    view.locator(".echo-panel .tree-key", has_text="linear_velocity").wait_for()
    assert "turtlesim/Pose" in view.locator(".echo-panel").inner_text()
    chatter_hz = float(row.locator("td").nth(4).inner_text())
    assert 7 < chatter_hz < 13
    page.shot("topics")


def test_teleop_pad_drives_the_turtle_and_the_plot_draws_its_x(page):
    page.open("turtlesim+plot")
    turtlesim, plot = page.view("turtlesim"), page.view("plot")
    turtlesim.locator("button", has_text="Reset").click()
    page.page.wait_for_function("minrosPage.views.get('turtlesim').turtles.some("
                                "(t) => t.name === 'turtle1' && t.pose && Math.abs(t.pose.x - 5.5444) < 0.01)",
                                timeout=15_000)
    plot.locator(".plot-input").fill("/turtle1/pose/x")
    plot.locator("button", has_text="Add").click()
    page.page.wait_for_function("minrosPage.views.get('plot').series.length === 1 && "
                                "minrosPage.views.get('plot').series[0].points > 10", timeout=15_000)
    start = page.js("minrosPage.views.get('plot').series[0].last")
    assert abs(start - 5.5444) < 0.01
    up = turtlesim.locator(".pad-ArrowUp")
    box = up.bounding_box()
    page.page.mouse.move(box["x"] + box["width"] / 2, box["y"] + box["height"] / 2)
    page.page.mouse.down()
    page.page.wait_for_function("minrosPage.views.get('plot').series[0].last > 8.5", timeout=15_000)
    page.page.mouse.up()
    # the pen drew a trail on the canvas, in turtlesim's default pen colour (179, 184, 255)
    trail = page.js("""(() => { const c = document.querySelector('.turtle-canvas').getContext('2d');
        const p = c.getImageData(Math.round(7 * 45), Math.round(499 - 5.5444 * 45), 1, 1).data;
        return [p[0], p[1], p[2]]; })()""")
    assert all(abs(a - b) < 30 for a, b in zip(trail, (179, 184, 255))), trail
    # and the keyboard drives it too (arrow keys while the view is shown)
    before = page.js("minrosPage.views.get('turtlesim').turtles.find((t) => t.name === 'turtle1').pose.theta")
    page.page.keyboard.down("ArrowLeft")
    page.page.wait_for_function(
        f"Math.abs(minrosPage.views.get('turtlesim').turtles.find((t) => t.name === 'turtle1').pose.theta - {before}) > 0.5",
        timeout=10_000)
    page.page.keyboard.up("ArrowLeft")
    page.page.wait_for_timeout(300)
    page.shot("turtlesim_teleop_plot")


def test_plot_several_series_pause_and_zoom(page):
    page.open("plot")
    plot = page.view("plot")
    plot.locator(".plot-input").fill("/turtle1/pose/x:y /turtle1/color_sensor")
    plot.locator("button", has_text="Add").click()
    page.page.wait_for_function("minrosPage.views.get('plot').series.length === 5", timeout=15_000)
    names = [s["name"] for s in page.js("minrosPage.views.get('plot').series")]
    assert names == ["/turtle1/pose/x", "/turtle1/pose/y", "/turtle1/color_sensor/r",
                     "/turtle1/color_sensor/g", "/turtle1/color_sensor/b"]
    page.page.wait_for_function("minrosPage.views.get('plot').series.every((s) => s.points > 180)", timeout=15_000)
    plot.locator("button", has_text="Pause").click()
    assert plot.locator("button", has_text="Resume").is_visible()
    paused = [s["points"] for s in page.js("minrosPage.views.get('plot').series")]
    chart = plot.locator(".u-over")
    box = chart.bounding_box()
    page.page.mouse.move(box["x"] + 10, box["y"] + 10)  # the first seconds, every value
    page.page.mouse.down()
    page.page.mouse.move(box["x"] + box["width"] * 0.25, box["y"] + box["height"] - 10, steps=5)
    page.page.mouse.up()
    # paused: the points keep arriving, the view stays
    page.page.wait_for_function(f"minrosPage.views.get('plot').series[0].points > {paused[0] + 30}")
    plot.locator("button", has_text="Resume").click()
    page.page.wait_for_timeout(300)
    page.shot("plot")


# -- images --------------------------------------------------------------------------------------

def test_image_topic_and_imshow_window_appear_as_pictures(page):
    page.open("images")
    view = page.view("images")
    for topic in ("/camera/image_raw", "/imshow/page_test"):
        view.locator(f'figure[data-topic="{topic}"] img').wait_for()
        page.page.wait_for_function(
            f"document.querySelector('figure[data-topic=\"{topic}\"] img').naturalWidth === 640", timeout=20_000)
    page.page.wait_for_timeout(1500)  # a rate reading
    page.shot("images")


# -- services and turtlesim --------------------------------------------------------------------

def test_spawn_from_the_services_view_adds_a_turtle_on_the_canvas(page):
    page.open("services")
    view = page.view("services")
    view.locator('a[data-service="/spawn"]').click()
    form = view.locator(".service-panel")
    form.locator('input[data-field="x"]').fill("2")
    form.locator('input[data-field="y"]').fill("8.5")
    form.locator('input[data-field="theta"]').fill("0.5")
    form.locator('input[data-field="name"]').fill("web_turtle")
    form.locator("button", has_text="Call").click()
    form.locator(".tree-value.string", has_text="web_turtle").wait_for(timeout=10_000)
    page.shot("services")
    page.page.goto(page.system.url + "#turtlesim")
    page.page.wait_for_function("minrosPage.views.get('turtlesim') && minrosPage.views.get('turtlesim').turtles.some("
                                "(t) => t.name === 'web_turtle' && t.pose && Math.abs(t.pose.y - 8.5) < 0.01)",
                                timeout=15_000)
    page.view("turtlesim").locator("select").select_option("web_turtle")
    page.page.wait_for_timeout(300)
    page.shot("turtlesim")


# -- parameters ----------------------------------------------------------------------------------

def test_parameter_edit_reaches_the_parameter_server(page, system):
    system.master.setParam("/page_test", "/page_test/gain", 1.5)
    page.open("params")
    view = page.view("params")
    row = view.locator('[data-param="/page_test/gain"]')
    view.locator("summary", has_text="page_test/").click()
    row.locator(".param-yaml").click()
    row.locator(".param-edit").fill("2.0")
    row.locator(".param-edit").press("Enter")
    wait_until(lambda: system.param("/page_test/gain") == 2.0, timeout=10, what="gain = 2.0")
    value = system.param("/page_test/gain")
    assert isinstance(value, float)  # typed as YAML: 2.0 stays a double
    row.locator(".param-yaml", has_text="2.0").wait_for()
    # a change made elsewhere is pushed to the page
    system.master.setParam("/page_test", "/page_test/gain", [1, 2, 3])
    row.locator(".param-yaml", has_text="[1, 2, 3]").wait_for(timeout=10_000)
    # a new one, typed as YAML
    view.locator(".param-name").fill("/page_test/names")
    view.locator(".param-value").fill("{first: a, second: 2}")
    view.locator("button", has_text="Set").click()
    wait_until(lambda: system.master.getParam("/t", "/page_test/names")[2] == {"first": "a", "second": 2},
               timeout=10, what="/page_test/names set")
    # dynamic_reconfigure: the server's form
    view.locator(".dynrec-list a", has_text="/dynamic_tutorials").click()
    field = view.locator('[data-dynparam="int_param"] input[type=number]')
    field.wait_for(timeout=10_000)
    field.fill("73")
    field.press("Enter")
    wait_until(lambda: system.master.getParam("/t", "/dynamic_tutorials/int_param")[2] == 73,
               timeout=10, what="int_param = 73 through dynamic_reconfigure")
    enum = view.locator('[data-dynparam="size"] select')
    assert "Medium (1)" in enum.inner_text()
    enum.select_option("3")
    wait_until(lambda: system.master.getParam("/t", "/dynamic_tutorials/size")[2] == 3,
               timeout=10, what="size = ExtraLarge")
    page.shot("params")


# -- console -------------------------------------------------------------------------------------

def test_a_urdf_parameter_reads_as_text_folded_under_its_first_line(page, system):
    """A long multi-line string (a URDF, as /robot_description holds) used to be one line of
    escaped "\\n"s; now it is folded under its first line and its size, opens as preformatted
    text, stays open while the tree is redrawn, and is edited in a text box."""
    urdf = (WEB / "scene_pkg" / "urdf" / "robot.urdf").read_text()
    name = "/page_test/robot_description"
    assert system.master.setParam("/t", name, urdf)[0] == 1
    page.open("params")
    view = page.view("params")
    view.locator("summary", has_text="page_test/").click()  # a new tab: the tree is folded
    row = view.locator(f'[data-param="{name}"]')
    text = row.locator("details.param-text")
    text.wait_for(timeout=10_000)
    lines = urdf.count("\n") + (0 if urdf.endswith("\n") else 1)
    summary = text.locator("summary").inner_text()
    assert summary.startswith('<?xml version="1.0"?>') and f"{lines} lines" in summary, summary
    pre = text.locator("pre")
    assert not pre.is_visible()  # folded: the tree stays readable
    text.locator("summary").click()
    assert pre.is_visible() and pre.text_content() == urdf
    # a string that is one line and its newline ("noetic\\n", as ROS sets it) stays a line
    distro = view.locator('[data-param="/rosdistro"]')
    assert distro.locator(".param-yaml").inner_text() == '"noetic\\n"'
    page.shot("params_urdf")
    # a change elsewhere redraws the tree: the text stays open
    assert system.master.setParam("/t", "/page_test/redraw", 1)[0] == 1
    view.locator('[data-param="/page_test/redraw"]').wait_for(timeout=10_000)
    assert row.locator("details.param-text pre").is_visible()
    row.locator("button", has_text="Edit").click()
    area = row.locator("textarea.param-edit-text")
    assert area.input_value() == urdf
    edited = urdf.replace('<robot name="scene_bot">', '<robot name="renamed_bot">')
    area.fill(edited)
    row.locator("button", has_text="Save").click()
    wait_until(lambda: system.param(name) == edited, timeout=10, what="the edited URDF")
    row.locator("details.param-text pre", has_text="renamed_bot").wait_for(timeout=10_000)


def test_console_filters_by_level_and_regex(page):
    page.open("console")
    view = page.view("console")
    page.page.wait_for_function("minrosPage.views.get('console').state.lines > 20", timeout=15_000)
    for level in ("debug", "info"):
        view.locator(f'input[data-level="{level}"]').uncheck()
    shown_levels = "[...new Set([...document.querySelectorAll('.view-console .console-row .c-level')].map((e) => e.textContent))].sort().join(',')"
    page.page.wait_for_function(f"{shown_levels} === 'ERROR,FATAL,WARN'", timeout=10_000)
    view.locator(".regex-input").fill("error line \\d+")
    page.page.wait_for_function(f"{shown_levels} === 'ERROR'", timeout=10_000)
    view.locator(".regex-input").fill("(unclosed")
    view.get_by_text("not a regular expression").wait_for()
    view.locator(".regex-input").fill("line")
    view.locator("button", has_text="Pause").click()
    paused = page.js("minrosPage.views.get('console').state")
    page.page.wait_for_function("minrosPage.views.get('console').state.pending > 0", timeout=10_000)
    assert page.js("minrosPage.views.get('console').state.lines") == paused["lines"]
    view.locator("button", has_text="Resume").click()
    view.locator(".console-row").first.click()
    page.shot("console")


@pytest.mark.timing
def test_console_takes_20000_lines_without_freezing(page, system):
    page.open("console")
    page.js("""window.frameGaps = []; (() => { let last = performance.now();
        const tick = (t) => { window.frameGaps.push(t - last); last = t; requestAnimationFrame(tick); };
        requestAnimationFrame(tick); })()""")
    burst = system.start([PYTHON, str(WEB / "page_sources.py"), "--log-burst", "20000",
                          "__name:=page_burst"])
    try:
        burst.read_until("BURST DONE", timeout=60)
        page.page.wait_for_function(
            "[...document.querySelectorAll('.console-row .c-msg')].some((m) => m.textContent === 'burst line 19999')",
            timeout=30_000)
    finally:
        burst.stop()
    state = page.js("minrosPage.views.get('console').state")
    assert state["lines"] == 20000  # rqt_console's limit: the oldest went first
    gaps = page.js("window.frameGaps.slice(1)")
    assert max(gaps) < 1000, f"the page froze for {max(gaps):.0f} ms"
    started = time.monotonic()
    page.view("console").locator('input[data-level="info"]').uncheck()
    page.page.wait_for_function("minrosPage.views.get('console').state.shown < 20000")
    assert time.monotonic() - started < 2.0
    page.shot("console_20000")


# -- publish -------------------------------------------------------------------------------------

def test_publish_yaml_at_a_rate_moves_the_turtle_until_stopped(page):
    page.open("publish+turtlesim")
    view = page.view("publish")
    turtle = "minrosPage.views.get('turtlesim').turtles.find((t) => t.name === 'turtle1').pose"
    view.locator(".topic-input").fill("/turtle1/cmd_vel")
    view.locator(".topic-input").press("Tab")
    page.page.wait_for_function("document.querySelector('.view-publish .publish-form input')", timeout=10_000)
    view.locator("select").select_option("yaml")
    view.locator(".yaml-input").fill("{linear: {x: 0.5}, angular: {z: 1.0}}")
    view.locator('input[type=number]').last.fill("10")
    view.locator("button", has_text="Publish").click()
    view.get_by_text("publishing on /turtle1/cmd_vel at 10 Hz").wait_for()
    page.page.wait_for_function(f"Math.abs({turtle}.angular_velocity - 1.0) < 1e-6", timeout=10_000)
    page.page.wait_for_timeout(1500)  # a circle on the canvas
    page.shot("publish")
    view.locator(".running button", has_text="Stop").click()
    # turtlesim stops a turtle 1 s after its last command
    page.page.wait_for_function(f"{turtle}.angular_velocity === 0", timeout=10_000)
    # once, from the form
    view.locator("select").select_option("form")
    view.locator('input[data-field="linear.x"]').fill("1.0")
    view.locator('input[type=number]').last.fill("0")
    view.locator("button", has_text="Publish").click()
    view.get_by_text("published once on /turtle1/cmd_vel").wait_for()
    page.page.wait_for_function(f"{turtle}.linear_velocity === 1", timeout=10_000)


# -- bad input -----------------------------------------------------------------------------------

def test_bad_input_is_reported_next_to_the_input_and_the_page_keeps_working(page):
    page.open("plot")
    plot = page.view("plot")
    plot.locator(".plot-input").fill("/turtle1/pose/nope")
    plot.locator("button", has_text="Add").click()
    plot.get_by_text("no field nope in topic /turtle1/pose").wait_for()
    plot.locator(".plot-input").fill("/no_such_topic/x")
    plot.locator("button", has_text="Add").click()
    plot.get_by_text("topic /no_such_topic/x does not exist").wait_for()
    page.shot("bad_plot_path")
    plot.locator(".plot-input").fill("/turtle1/pose/x")
    plot.locator("button", has_text="Add").click()
    page.page.wait_for_function("minrosPage.views.get('plot').series.length === 1 && "
                                "minrosPage.views.get('plot').series[0].points > 5", timeout=15_000)
    assert not plot.locator(".error-line.visible").count()

    page.page.goto(page.system.url + "#params")
    params = page.view("params")
    params.locator(".param-name").fill("/page_test/broken")
    params.locator(".param-value").fill("[1, 2")
    params.locator("button", has_text="Set").click()
    params.get_by_text("YAML does not parse: line 1, column 6").wait_for()
    page.shot("bad_yaml")
    params.locator(".param-value").fill("[1, 2]")
    params.locator("button", has_text="Set").click()
    params.locator('[data-param="/page_test/broken"]').wait_for(timeout=10_000)

    page.page.goto(page.system.url + "#services")
    services = page.view("services")
    services.locator('a[data-service="/kill"]').click()
    services.locator('input[data-field="name"]').fill("nobody")
    services.locator("button", has_text="Call").click()
    error = services.locator(".error-line.visible")
    error.wait_for(timeout=10_000)
    assert "service" in error.inner_text().lower()
    page.shot("bad_service_call")
    services.locator('a[data-service="/clear"]').click()
    services.locator("button", has_text="Call").click()
    services.get_by_text("called at").wait_for(timeout=10_000)

    page.page.goto(page.system.url + "#publish")
    publish = page.view("publish")
    publish.locator(".topic-input").fill("/turtle1/cmd_vel")
    publish.locator(".topic-input").press("Tab")
    publish.locator("select").select_option("yaml")
    publish.locator(".yaml-input").fill("{linear: {q: 1}}")
    publish.locator("button", has_text="Publish").click()
    publish.get_by_text("No field name [linear.q]").wait_for()
    publish.locator(".yaml-input").fill("{linear: {x: [}")
    publish.locator("button", has_text="Publish").click()
    publish.get_by_text("YAML does not parse").wait_for()


def test_page_works_behind_a_token(browser, system, shots):
    """With --token the page's address carries ?token=; its scripts load without it, and the
    WebSocket and the pictures use it."""
    port = free_port()
    web = system.start([PYTHON, "-m", "minros", "web", "--port", str(port), "--token", "s3cret",
                        "__name:=token_web"])
    web.read_until("listening on", timeout=30)
    tab = Page(browser, system, shots)
    try:
        denied = tab.context.request.get(f"http://127.0.0.1:{port}/")
        assert denied.status == 401 and "wrong or missing token" in denied.text()
        script = tab.context.request.get(f"http://127.0.0.1:{port}/js/app.js")
        assert script.status == 200
        tab.page.goto(f"http://127.0.0.1:{port}/?token=s3cret#images")
        tab.page.wait_for_function("minrosPage.conn.state === 'connected' && minrosPage.graph.version > 0",
                                   timeout=20_000)
        tab.page.wait_for_function(
            "document.querySelector('figure[data-topic=\"/camera/image_raw\"] img')?.naturalWidth === 640",
            timeout=20_000)
    finally:
        tab.close()
        web.stop()


# -- the other views, phone layout ------------------------------------------------------------

def test_wire_and_about_views(page):
    page.open("wire")  # this server follows no trace: the view says how to start a traced run
    wire = page.view("wire")
    wire.locator(".wire-help").get_by_text("minros web --trace run.jsonl").wait_for()
    assert "minros trace -o run.jsonl -- roslaunch" in wire.locator(".wire-help").inner_text()
    assert wire.locator(".toolbar").is_hidden()
    page.shot("wire_no_trace")  # wire.png is test_page_wire.py's, on a traced run
    page.page.goto(page.system.url + "#about")
    page.view("about").get_by_text("rosbridge v2").wait_for()


def test_phone_layout(browser, system, shots):
    tab = Page(browser, system, shots, width=390, height=844)
    try:
        tab.open("turtlesim")
        tab.view("turtlesim").locator(".turtle-canvas").wait_for()
        nav = tab.js("(() => { const r = document.querySelector('nav.menu').getBoundingClientRect(); return [r.width, r.height]; })()")
        assert nav[0] >= 380 and nav[1] < 60  # the menu is a bar on top
        assert tab.js("document.documentElement.scrollWidth") <= 390  # nothing wider than the phone
        canvas = tab.js("document.querySelector('.turtle-canvas').getBoundingClientRect().width")
        assert 300 < canvas <= 390
        tab.page.wait_for_timeout(500)
        tab.shot("phone_turtlesim")
        tab.page.goto(system.url + "#graph")
        tab.view("graph").locator('.vertex[data-id="n:/turtlesim"]').wait_for()
        tab.page.wait_for_timeout(300)
        tab.shot("phone_graph")
    finally:
        tab.close()


# -- performance ---------------------------------------------------------------------------------

@pytest.mark.timeout(SOAK_SECONDS + 120)
def test_1khz_plot_beside_a_30hz_vga_picture_keeps_30_fps_and_bounded_memory(browser, system, shots):
    sources = system.start([PYTHON, str(WEB / "page_sources.py"), "--signal", "1000", "--image", "30",
                            "__name:=perf_sources", "/camera/image_raw:=/perf/image"])
    sources.read_until("READY", timeout=30)
    tab = Page(browser, system, shots)
    cdp = tab.context.new_cdp_session(tab.page)
    cdp.send("Performance.enable")
    try:
        tab.open("plot+images")
        images = tab.view("images")
        images.locator('figure[data-topic="/perf/image"] img').wait_for(timeout=20_000)
        tab.page.wait_for_function(
            "document.querySelector('figure[data-topic=\"/perf/image\"] img').naturalWidth === 640", timeout=20_000)
        tab.view("plot").locator(".plot-input").fill("/signal/data")
        tab.view("plot").locator("button", has_text="Add").click()
        tab.page.wait_for_function("minrosPage.views.get('plot').series.length === 1", timeout=15_000)
        tab.js("""window.frames_ = 0; (() => { const tick = () => { window.frames_++; requestAnimationFrame(tick); };
            requestAnimationFrame(tick); })()""")
        tab.page.wait_for_timeout(3000)  # warm up
        samples = []
        window = min(5.0, SOAK_SECONDS / 3)
        deadline = time.monotonic() + SOAK_SECONDS
        while time.monotonic() < deadline:
            frames0 = tab.js("window.frames_")
            points0 = tab.js("minrosPage.views.get('plot').series[0].points")
            t0 = time.monotonic()
            tab.page.wait_for_timeout(window * 1000)
            elapsed = time.monotonic() - t0
            fps = (tab.js("window.frames_") - frames0) / elapsed
            cdp.send("HeapProfiler.collectGarbage")
            metrics = {m["name"]: m["value"] for m in cdp.send("Performance.getMetrics")["metrics"]}
            samples.append({"fps": fps, "heap": metrics["JSHeapUsedSize"], "nodes": metrics["Nodes"],
                            "points": tab.js("minrosPage.views.get('plot').series[0].points"),
                            "points_growth_per_s": (tab.js("minrosPage.views.get('plot').series[0].points") - points0) / elapsed})
        tab.shot("performance_plot_and_image")
    finally:
        tab.close()
        sources.stop()
    report = json.dumps(samples, indent=1)
    print("page performance:", report)
    # 30 fps or more (58-60 on an idle machine); one window of a machine shared with other
    # work may dip, a frozen page would not get near 20
    fps = sorted(s["fps"] for s in samples)
    assert fps[len(fps) // 2] >= 30 and fps[0] >= 20, report
    # the plot kept (up to) its 60 s of a ~1 kHz signal
    assert samples[-1]["points"] > 800 * min(SOAK_SECONDS, 55), report
    # memory: after the first window, the heap and the DOM do not keep growing
    first, last = samples[0], samples[-1]
    assert last["heap"] < first["heap"] * 1.5 + 8e6, report
    assert last["nodes"] < first["nodes"] * 1.5 + 500, report
