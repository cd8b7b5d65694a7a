"""The web page's server side without sockets: rqt_plot's field paths, the page's data (graph,
rates, log ring, echo trees, typed YAML, parameter pushes) and the page session's replies to
bad input, driven through a fake WebState and a real Outbox."""

from __future__ import annotations

import json
import math

import pytest

from minros.msgs import Time, get_message_class
from minros.web import pagemodel, plotpath
from minros.web.outbox import Outbox
from minros.web.rosapi import Graph
from minros.web.state import apply_param_update

TYPES = {"/turtle1/pose": "turtlesim/Pose", "/imu": "sensor_msgs/Imu", "/tf": "tf2_msgs/TFMessage",
         "/joints": "sensor_msgs/JointState", "/chatter": "std_msgs/String", "/flag": "std_msgs/Bool",
         "/turtle1": "std_msgs/Float64", "/odd": "*"}


def fields(path: str) -> list:
    return [f.name for f in plotpath.plot_fields(path, TYPES, get_message_class)[0]]


# -- rqt_plot's paths ----------------------------------------------------------------------------

def test_expressions_split_like_rqt_plot_arguments():
    assert plotpath.split_expressions("/turtle1/pose/x:y:theta") == [
        "/turtle1/pose/x", "/turtle1/pose/y", "/turtle1/pose/theta"]
    assert plotpath.split_expressions(" /a/x, /b/y  /c/z ") == ["/a/x", "/b/y", "/c/z"]
    assert plotpath.split_expressions("a/x") == ["/a/x"]
    with pytest.raises(plotpath.PlotPathError, match="must contain a topic and field name"):
        plotpath.split_expressions("x:y")
    with pytest.raises(plotpath.PlotPathError, match="type a field path"):
        plotpath.split_expressions("  ")


def test_paths_resolve_to_series_as_rqt_plot_does():
    assert fields("/turtle1/pose/x") == ["/turtle1/pose/x"]
    # the longest topic wins: /turtle1/pose, not /turtle1 with a field "pose"
    assert plotpath.find_topic("/turtle1/pose/x", TYPES)[0] == "/turtle1/pose"
    # a message plots its numeric, non-array fields
    assert fields("/turtle1/pose") == [f"/turtle1/pose/{f}" for f in
                                       ("x", "y", "theta", "linear_velocity", "angular_velocity")]
    assert fields("/imu/orientation") == [f"/imu/orientation/{c}" for c in "xyzw"]
    # a fixed-size array plots each element; an index picks one
    assert fields("/imu/orientation_covariance") == [f"/imu/orientation_covariance[{i}]" for i in range(9)]
    assert fields("/imu/orientation_covariance[4]") == ["/imu/orientation_covariance[4]"]
    assert fields("/tf/transforms[0]/transform/translation/x") == ["/tf/transforms[0]/transform/translation/x"]
    assert fields("/joints/position[1]") == ["/joints/position[1]"]
    assert fields("/flag/data") == ["/flag/data"]
    assert fields("/imu/header/stamp") == ["/imu/header/stamp"]


@pytest.mark.parametrize("path, text", [
    ("/nothing/x", "topic /nothing/x does not exist"),
    ("/turtle1/pose/nope", "no field nope in topic /turtle1/pose"),
    ("/turtle1/pose/x/deeper", "no field x/deeper in topic /turtle1/pose"),
    ("/joints/position", "topic /joints/position is variable-size numeric array: index it"),
    ("/tf/transforms/transform", "/tf/transforms is an array: index it, e.g. /tf/transforms[0]"),
    ("/tf/transforms", "/tf/transforms is an array of geometry_msgs/TransformStamped"),
    ("/chatter/data", "Topic /chatter/data is not numeric"),
    ("/imu/orientation_covariance[9]", "has 9 elements: [9] is out of range"),
    ("/turtle1/pose/x[0]", "/turtle1/pose/x is not an array: remove [0]"),
    ("/turtle1/pose/x-y", "invalid field x-y in topic /turtle1/pose"),
    ("/odd/x", "type of topic /odd/x is unknown"),
    ("/chatter", "No plottable fields in /chatter"),
])
def test_bad_paths_say_what_is_wrong(path, text):
    with pytest.raises(plotpath.PlotPathError) as info:
        plotpath.plot_fields(path, TYPES, get_message_class)
    assert text in str(info.value)


def test_values_and_x_follow_rqt_plot():
    Imu = get_message_class("sensor_msgs/Imu")
    imu = Imu()
    imu.header.stamp = Time(10, 500_000_000)
    imu.orientation_covariance = [float(i) for i in range(9)]
    series = plotpath.resolve("/imu/orientation_covariance[4] /imu/header/stamp", TYPES, get_message_class)
    assert [s.value(imu) for s in series] == [4.0, 10.5]
    assert plotpath.stamp_of(imu, 99.0) == 10.5  # a header: its stamp
    Pose = get_message_class("turtlesim/Pose")
    assert plotpath.stamp_of(Pose(x=1.0), 99.0) == 99.0  # none: arrival time
    Joints = get_message_class("sensor_msgs/JointState")
    assert plotpath.resolve("/joints/position[3]", TYPES, get_message_class)[0].value(Joints(position=[1.0])) is None
    flag = plotpath.resolve("/flag/data", TYPES, get_message_class)[0]
    assert flag.value(get_message_class("std_msgs/Bool")(data=True)) == 1.0
    repeated = plotpath.resolve("/turtle1/pose/x /turtle1/pose/x:y", TYPES, get_message_class)
    assert [f.name for f in repeated] == ["/turtle1/pose/x", "/turtle1/pose/y"]
    groups = plotpath.group_by_topic(plotpath.resolve("/imu/orientation/x /turtle1/pose/y /imu/orientation/w",
                                                      TYPES, get_message_class))
    assert {t: [i for i, _f in g] for t, g in groups.items()} == {"/imu": [0, 2], "/turtle1/pose": [1]}


# -- page data -----------------------------------------------------------------------------------

def test_graph_json_and_node_info():
    graph = Graph(topic_types={"/chatter": "std_msgs/String", "/cmd": "geometry_msgs/Twist"},
                  publishers={"/chatter": ["/talker"]},
                  subscribers={"/chatter": ["/listener", "/b"], "/cmd": ["/talker"]},
                  services={"/talker/get_loggers": ["/talker"]})
    msg = pagemodel.graph_json(graph, 7, "push")
    assert msg["op"] == "graph" and msg["version"] == 7 and msg["mode"] == "push"
    assert msg["nodes"] == ["/b", "/listener", "/talker"]
    assert msg["topics"][0] == {"name": "/chatter", "type": "std_msgs/String", "publishers": ["/talker"],
                                "subscribers": ["/b", "/listener"]}
    assert msg["services"] == [{"name": "/talker/get_loggers", "providers": ["/talker"]}]
    info = pagemodel.node_info(graph, "/talker")
    assert info["publications"] == [["/chatter", "std_msgs/String"]]
    assert info["subscriptions"] == [["/cmd", "geometry_msgs/Twist"]]
    assert info["services"] == ["/talker/get_loggers"]
    rows = [[1, "/listener", "o", "TCPROS", "/chatter", True, "..."],
            [2, "http://x:1/", "i", "TCPROS", "/cmd", 0], "garbage", [3]]
    assert pagemodel.connections(rows) == [{"topic": "/chatter", "to": "/listener",
                                            "direction": "outbound", "transport": "TCPROS"}]
    assert pagemodel.connections("not a list") == []


def test_topic_meter_rate_bandwidth_over_a_window():
    meter = pagemodel.TopicMeter(window=5.0)
    assert meter.sample(0.0, 0, 0)["hz"] is None
    stats = meter.sample(1.0, 10, 1000)
    assert stats == {"count": 10, "hz": 10.0, "bw": 1000.0, "size": 100.0}
    for t in range(2, 12):
        stats = meter.sample(float(t), 10 + 20 * (t - 1), 1000 + 400 * (t - 1))
    assert stats["hz"] == pytest.approx(20.0) and stats["bw"] == pytest.approx(400.0)
    assert len(meter.samples) <= 7  # the window, not the history
    stats = meter.sample(12.0, 210, 5000)
    assert stats["size"] is not None
    idle = meter.sample(40.0, 210, 5000)
    assert idle["hz"] == 0.0 and idle["size"] is None


def test_log_ring_keeps_the_newest_and_answers_since():
    Log = get_message_class("rosgraph_msgs/Log")
    ring = pagemodel.LogRing(size=5)
    for i in range(8):
        msg = Log(level=Log.WARN, name="/n", msg=f"line {i}", file="f.py", function="fn", line=i,
                  topics=["/rosout"])
        msg.header.stamp = Time(100, i)
        ring.add(msg)
    assert [line[0] for line in ring.lines] == [4, 5, 6, 7, 8]
    assert [line[4] for line in ring.since(6)] == ["line 6", "line 7"]
    assert [line[0] for line in ring.since(0)] == [4, 5, 6, 7, 8]  # older ones are gone
    assert [line[0] for line in ring.since(0, limit=2)] == [7, 8]
    assert ring.since(8) == []
    assert ring.lines[-1][1:] == [100.000000007, 4, "/n", "line 7", "f.py", "fn", 7, ["/rosout"]]


def test_message_tree_cuts_what_a_browser_cannot_show():
    Image = get_message_class("sensor_msgs/Image")
    image = Image(height=480, width=640, encoding="bgr8", step=1920, data=bytes(range(256)) * 3600)
    tree = pagemodel.message_tree(image, max_items=4)
    assert tree["width"] == 640 and tree["encoding"] == "bgr8"
    assert tree["data"] == "[921600 bytes] 00 01 02 03 ... 921596 more"
    assert tree["header"]["stamp"] == {"secs": 0, "nsecs": 0}
    Joints = get_message_class("sensor_msgs/JointState")
    joints = pagemodel.message_tree(Joints(position=[math.nan, math.inf, 1.0, 2.0, 3.0]), max_items=3)
    assert joints["position"] == ["nan", "inf", 1.0, "... 2 more of 5"]
    long = pagemodel.message_tree(get_message_class("std_msgs/String")(data="x" * 50), max_chars=10)
    assert long["data"] == "x" * 10 + "... 40 more characters"
    json.dumps(tree, allow_nan=False)
    json.dumps(joints, allow_nan=False)


def test_typed_yaml_round_trips_and_errors_name_the_place():
    for value in (1, 1.0, "1", "yes", True, [1, 2.5, "a"], {"a": {"b": [1]}}, {}, "two\nlines", 1e-9):
        text = pagemodel.dumps_yaml(value)
        back = pagemodel.parse_yaml(text)
        assert back == value and type(back) is type(value), (value, text)
    assert pagemodel.dumps_yaml(1.0) == "1.0" and pagemodel.dumps_yaml([1, 2]) == "[1, 2]"
    with pytest.raises(pagemodel.YamlError, match=r"YAML does not parse: line 1, column 6: "):
        pagemodel.parse_yaml("[1, 2")
    with pytest.raises(pagemodel.YamlError, match=r"line 2"):
        pagemodel.parse_yaml("a: 1\n b: : 2")
    assert pagemodel.param_leaves({"/b": 1.5, "/a/x": "s", "/a/y": {}}) == [
        ["/a/x", "s", "string"], ["/a/y", "{}", "dict"], ["/b", "1.5", "double"]]


def test_param_updates_change_the_flat_table():
    flat = {"/a/b": 1, "/a/c": 2, "/d": 3}
    assert apply_param_update(flat, "/a/", {"b": 1, "e": {"f": 4}}) == ({"/a/e/f": 4}, ["/a/c"])
    assert flat == {"/a/b": 1, "/a/e/f": 4, "/d": 3}
    assert apply_param_update(flat, "/a/e/", {}) == ({}, ["/a/e/f"])  # a delete is {}
    assert apply_param_update(flat, "/d/x/", 5) == ({"/d/x": 5}, ["/d"])  # a value became a namespace
    assert apply_param_update(flat, "/", {"z": 1}) == ({"/z": 1}, ["/a/b", "/d/x"])
    assert apply_param_update(flat, "/z", 1) == ({}, [])  # no change, nothing to tell


# -- the page session's answers ------------------------------------------------------------------

class FakeState:
    """What PageSession uses of WebState, without ROS."""

    def __init__(self) -> None:
        self.graph = Graph(topic_types=dict(TYPES))
        self.graph_version = 1
        self.graph_mode = "push"
        self.started = 1.0
        self.taps = {}
        self.publishers = {}
        self.params = {}
        self.tapped = []

    def refresh_graph(self):
        return self.graph

    def topic_allowed(self, topic):
        return True

    def topic_type(self, topic):
        return self.graph.topic_types.get(topic)

    def message_class(self, type_name):
        return get_message_class(type_name)

    def tap(self, topic, type_name, key, listener):
        self.tapped.append((topic, key))

    def untap(self, topic, key):
        self.tapped.remove((topic, key))

    def add_graph_listener(self, key, listener):
        pass

    def remove_graph_listener(self, key):
        pass

    def now(self):
        return Time(1, 0)

    def set_param(self, name, value):
        self.params[name] = value


class FakeHub:
    def __init__(self, wire=None, learn=None) -> None:
        from minros.web.scene import SceneHub

        self.sessions = []
        self.wire = wire
        self.learn = learn
        self.scene = SceneHub(state=None)

    def add(self, session):
        self.sessions.append(session)

    def remove(self, session):
        self.sessions.remove(session)


def session(wire=None, learn=None, local=True, client_id="test"):
    from minros.web.page import PageSession

    outbox = Outbox()
    state = FakeState()
    sent = PageSession(client_id, state, outbox, lambda reason: None, FakeHub(wire, learn),
                       run_async=lambda fn: fn(), local=local)
    return sent, outbox, state


def replies(outbox: Outbox) -> list:
    out = []
    while True:
        got = outbox.get(timeout=0)
        if got is None:
            return out
        slot, item = got
        frames = item if slot is None else slot.render(item)
        for frame in [frames] if isinstance(frames, (str, bytes)) else frames:
            out.append(json.loads(frame))


def test_session_says_hello_and_answers_bad_input_next_to_the_request():
    page, outbox, state = session()
    page.start()
    hello = replies(outbox)[0]
    assert hello["op"] == "hello" and hello["graph_mode"] == "push" and hello["wire"] is False
    assert "/rosout" in hello["quiet"]
    page.receive(json.dumps({"op": "plot", "id": "p", "expr": "/turtle1/pose/nope"}))
    assert replies(outbox) == [{"op": "reply", "id": "p", "error": "no field nope in topic /turtle1/pose"}]
    assert state.tapped == []
    page.receive(json.dumps({"op": "param_set", "id": "s", "name": "/x", "yaml": "[1, 2"}))
    error = replies(outbox)[0]["error"]
    assert error.startswith("YAML does not parse: line 1, column 6")
    assert state.params == {}
    page.receive(json.dumps({"op": "param_set", "id": "s2", "name": "/x", "yaml": "{a: 1.0}"}))
    assert replies(outbox) == [{"op": "reply", "id": "s2", "yaml": "{a: 1.0}", "type": "dict"}]
    assert state.params == {"/x": {"a": 1.0}}
    page.receive(json.dumps({"op": "param_set", "id": "s3", "name": "relative", "yaml": "1"}))
    assert "start 'relative' with /" in replies(outbox)[0]["msg"]  # a rosbridge status, with the id
    page.receive(json.dumps({"op": "pub_start", "id": "q", "topic": "/turtle1/cmd_vel",
                             "type": "geometry_msgs/Twist", "yaml": "{linear: {q: 1}}"}))
    assert replies(outbox) == [{"op": "reply", "id": "q",
                                "error": "geometry_msgs/Twist: No field name [linear.q]"}]
    page.receive(json.dumps({"op": "pub_start", "id": "q2", "topic": "/turtle1/cmd_vel",
                             "type": "geometry_msgs/Twist", "yaml": "{}", "rate": 5000}))
    assert "out of range" in replies(outbox)[0]["msg"]
    page.receive(json.dumps({"op": "echo", "id": "e", "topic": "/missing"}))
    assert replies(outbox)[0]["error"].startswith("topic /missing does not exist")


def test_session_plot_taps_one_subscription_per_topic_and_batches_points():
    page, outbox, state = session()
    page.receive(json.dumps({"op": "plot", "id": 1, "expr": "/turtle1/pose/x:y /imu/orientation/w"}))
    reply = replies(outbox)[0]
    assert reply["series"] == ["/turtle1/pose/x", "/turtle1/pose/y", "/imu/orientation/w"]
    assert sorted(t for t, _key in state.tapped) == ["/imu", "/turtle1/pose"]
    entry = page.plots[1]
    entry.add("/turtle1/pose", 1.0, [5.0, 6.0])
    entry.add("/turtle1/pose", 1.1, [5.5, math.nan])
    data = entry.drain()
    assert data == [{"topic": "/turtle1/pose", "series": [0, 1], "x": [1.0, 1.1], "y": [[5.0, 5.5], [6.0, None]]}]
    assert entry.drain() == []
    page.receive(json.dumps({"op": "unplot", "id": 1}))
    assert state.tapped == []
    from minros.web.page import MAX_PLOTS

    for i in range(MAX_PLOTS + 1):  # a page cannot open plots without bound
        page.receive(json.dumps({"op": "plot", "id": i, "expr": "/turtle1/pose/x"}))
    last = replies(outbox)[-1]
    assert last["op"] == "status" and f"{MAX_PLOTS} plots are running already" in last["msg"]
    assert len(page.plots) == MAX_PLOTS
    page.close()
    assert state.tapped == []


# -- the static page -----------------------------------------------------------------------------

def test_page_files_load_offline_and_ship_in_the_wheel():
    """Every module the page imports exists, nothing is fetched from the internet, the vendored
    libraries keep their licences, and pyproject puts the folder into the wheel."""
    import re
    from pathlib import Path

    try:
        import tomllib
    except ModuleNotFoundError:  # Python 3.10: the same parser, from PyPI
        import tomli as tomllib

    import minros.web

    static = Path(minros.web.__file__).parent / "static"
    index = (static / "index.html").read_text(encoding="utf-8")
    # the import map names the bare modules (three.js's examples import "three")
    imports = json.loads(re.search(r'<script type="importmap">(.*?)</script>', index, re.S).group(1))["imports"]
    bare = {name: (static / target).resolve() for name, target in imports.items()}
    pending = [static / "index.html"]
    seen = set()
    while pending:
        path = pending.pop()
        if path in seen:
            continue
        seen.add(path)
        text = path.read_text(encoding="utf-8")
        if path.parent.name not in ("uplot", "dagre"):
            assert not re.search(r"""(src|href|from)\s*=?\s*["']https?://""", text), path
        refs = re.findall(r"""(?:src|href)="([^"#:]+\.(?:js|css))"|^\s*(?:import|export)\b[^;'"]*?\bfrom\s*["']([^"']+)["']|^\s*import\s*["']([^"']+)["']|\bimport\(\s*["']([^"']+)["']\s*\)""",
                          text, re.M)
        for ref in refs:
            name = next(r for r in ref if r)
            target = bare.get(name) or (path.parent / name).resolve()
            if not ref[0]:  # a module: relative, or named by the import map
                assert name in bare or name.startswith("."), f"{path.relative_to(static)} imports {name}"
            assert target.is_file(), f"{path.relative_to(static)} refers to a missing {target}"
            pending.append(target)
    for needed in ("js/views/console.js", "vendor/uplot/uPlot.esm.js", "js/view3d/view.js",
                   "vendor/three/build/three.core.js",
                   "vendor/three/examples/jsm/loaders/collada/ColladaParser.js"):
        assert static / needed in seen, needed
    for lib in ("uplot", "dagre", "three"):
        assert "Permission is hereby granted" in (static / "vendor" / lib / "LICENSE").read_text()
    with open(Path(__file__).resolve().parents[2] / "pyproject.toml", "rb") as f:
        package_data = tomllib.load(f)["tool"]["setuptools"]["package-data"]
    assert "static/**/*" in package_data["minros.web"]
