"""Pure pieces of the command-line tools: YAML message filling, echo formatting, field
selection, output comparison, graph building/layout, rate statistics, rosparam helpers."""

from __future__ import annotations

import xml.etree.ElementTree as ET
import xmlrpc.client

import pytest

from compare import Outcome, differences, normalize
from minros.exceptions import MessageException
from minros.msgs import Duration, Time, fill, get_message_class
from minros.tools import echo
from minros.tools.decode import DecodeError, load_class

PoseStamped = get_message_class("geometry_msgs/PoseStamped")
Point = get_message_class("geometry_msgs/Point")
Header = get_message_class("std_msgs/Header")


# ---------------------------------------------------------------------------------------------
# fill

def test_fill_positional_dict_and_nested() -> None:
    p = Point()
    fill.fill_message_args(p, [1, 2.5, -3])
    assert (p.x, p.y, p.z) == (1, 2.5, -3)
    m = PoseStamped()
    fill.fill_message_args(m, [{"header": {"frame_id": "map", "stamp": 1500000000}, "pose": {"position": {"x": 4}}}])
    assert m.header.frame_id == "map" and m.header.stamp == Time(1, 500000000) and m.pose.position.x == 4
    fill.fill_message_args(m, ["auto", [[1.0, 2.0, 3.0], [0.0, 0.0, 0.0, 1.0]]], fill.substitution_keys(Time(7, 0)))
    assert m.header.stamp == Time(7, 0) and m.pose.position.z == 3.0 and m.pose.orientation.w == 1.0


def test_fill_now_auto_and_message_arrays() -> None:
    keys = fill.substitution_keys(Time(5, 6))
    h = Header()
    fill.fill_message_args(h, [{"stamp": "now", "frame_id": "x"}], keys)
    assert h.stamp == Time(5, 6)
    m = PoseStamped()
    fill.fill_message_args(m, [{"header": "auto"}], keys)
    assert m.header.stamp == Time(5, 6)
    Path = get_message_class("nav_msgs/Path")
    path = Path()
    fill.fill_message_args(path, [{"poses": [{"pose": {"position": {"x": 1}}}, {}]}])
    assert len(path.poses) == 2 and path.poses[0].pose.position.x == 1
    Dur = get_message_class("std_msgs/Duration")
    d = Dur()
    fill.fill_message_args(d, [2000000000])
    assert d.data == Duration(2, 0)


@pytest.mark.parametrize("msg_class,args,text", [
    (Point, [{"w": 1}], "No field name [w]"),
    (Point, [1, 2], "Not enough arguments"),
    (Point, [1, 2, 3, 4], "Too many arguments"),
    (PoseStamped, [{"header": {"stamp": "later"}}], "No key named [later]"),
    (PoseStamped, [{"pose": {"position": {"q": 1}}}], "No field name [pose.position.q]"),
    (get_message_class("std_msgs/Float64MultiArray"), [{"data": 3}], "must be a list or tuple"),
    (get_message_class("geometry_msgs/PoseWithCovariance"), [{"covariance": [1.0]}], "incorrect number of elements: 1 != 36"),
])
def test_fill_errors(msg_class, args, text) -> None:
    with pytest.raises(MessageException, match=r".*" + text.replace("[", r"\[").replace("]", r"\]")):
        fill.fill_message_args(msg_class(), args)


def test_printable_message_args() -> None:
    assert fill.printable_message_args(PoseStamped) == (
        "header.seq header.stamp header.frame_id pose.position.x pose.position.y pose.position.z "
        "pose.orientation.x pose.orientation.y pose.orientation.z pose.orientation.w")
    assert fill.printable_message_args(get_message_class("std_msgs/Empty")) == ""


# ---------------------------------------------------------------------------------------------
# echo formatting

def test_field_path_parsing() -> None:
    assert echo.parse_field_path("/a/b[1]/c[1:3]/d[::2]") == [
        ("a", None), ("b", 1), ("c", slice(1, 3)), ("d", slice(None, None, 2))]
    for bad, text in (("/a[x]", "non-integer array index"), ("/a[1", "missing closing"),
                      ("/a[]", "empty array index"), ("/a[1:2:3:4]", "too many slice")):
        with pytest.raises(echo.FieldError, match=text):
            echo.parse_field_path(bad)


def test_field_getter_and_type() -> None:
    Path = get_message_class("nav_msgs/Path")
    path = Path(poses=[PoseStamped(), PoseStamped()])
    path.poses[1].pose.position.x = 3.0
    get = echo.make_field_getter("/poses[1]/pose/position/x")
    assert get(path) == 3.0
    assert echo.make_field_getter("/poses[0:2]/pose/position/x")(path) == [0.0, 3.0]
    assert echo.field_type(Path, "poses/pose/position/x") == "float64"
    assert echo.field_type(PoseStamped, "header/stamp") == "time"
    assert echo.field_type(PoseStamped, "nope") is None


def test_noarr_nostr_placeholders() -> None:
    Image = get_message_class("sensor_msgs/Image")
    img = Image(height=1, width=3, encoding="mono8", step=3, data=b"\x01\x02\x03")
    text = echo.yaml_text(img, value_transform=echo.make_value_transform(True, True))
    assert 'encoding: "<string length: 5>"' in text
    assert 'data: "<array type: uint8, length: 3>"' in text
    assert "frame_id: \"<string length: 0>\"" in text
    assert echo.yaml_text(img.data, "uint8[]") == "[1, 2, 3]"
    assert echo.yaml_text(Point(1.0, 2.0, 3.0)) == "x: 1.0\ny: 2.0\nz: 3.0"


def test_plot_format() -> None:
    m = PoseStamped()
    m.header.stamp = Time(2, 5)
    m.header.frame_id = "f"
    assert echo.plot_header(m, None) == ("%time,field.header.seq,field.header.stamp,field.header.frame_id,"
                                         "field.pose.position.x,field.pose.position.y,field.pose.position.z,"
                                         "field.pose.orientation.x,field.pose.orientation.y,"
                                         "field.pose.orientation.z,field.pose.orientation.w")
    assert echo.plot_line(m, Time(9, 0)) == "2000000005,0,2000000005,f,0.0,0.0,0.0,0.0,0.0,0.0,0.0"
    flt = echo.make_field_filter(nostr=True, noarr=False)
    assert echo.plot_line(Point(1.0, 2.0, 3.0), Time(1, 0), field_filter=flt) == "1000000000,1.0,2.0,3.0"
    assert echo.plot_line(m, Time(9, 0), field_filter=flt).count(",") == 9


# ---------------------------------------------------------------------------------------------
# decode

def test_load_class_prefers_installed_then_definition() -> None:
    assert load_class("geometry_msgs/Point", Point._md5sum, "") is Point
    custom = load_class("nobody/Thing", "0123", "int32 a\nstring b\n")
    assert custom.__slots__ == ["a", "b"] or list(custom.__slots__) == ["a", "b"]
    mismatched = load_class("geometry_msgs/Point", "ffff", "float32 x\n")
    assert mismatched is not Point and list(mismatched._slot_types) == ["float32"]
    with pytest.raises(DecodeError, match="not installed"):
        load_class("nobody/Other", "1", "")


# ---------------------------------------------------------------------------------------------
# compare

def test_normalize_masks_only_volatile_parts() -> None:
    a = "Pid: 123\n * /rostopic_4411_1700000000123 (http://localhost:40001/)\ntime=1.25ms\n  secs: 17\n"
    b = "Pid: 999\n * /rostopic_77_1700000999999 (http://localhost:41234/)\ntime=9.00ms\n  secs: 18\n"
    assert normalize(a) == normalize(b)
    assert normalize("Type: std_msgs/String") != normalize("Type: std_msgs/Int32")
    ours = Outcome(["x"], 0, "a\nb\n", "")
    assert differences(ours, Outcome(["y"], 0, "a\nb\n", "")) == []
    problems = differences(ours, Outcome(["y"], 1, "a\nc\n", ""))
    assert "exit status 0 != reference 1" in problems[0] and "-c" in problems[1] and "+b" in problems[1]


# ---------------------------------------------------------------------------------------------
# graph

STATE = (
    [["/chatter", ["/talker"]], ["/rosout", ["/talker", "/listener"]], ["/unheard", ["/talker"]]],
    [["/chatter", ["/listener", "/rostopic_1_2"]], ["/rosout", ["/rosout"]], ["/lonely", ["/listener"]]],
    [],
)


def test_build_graph_hides_debug_like_rqt_graph() -> None:
    from minros.cli import graph

    g = graph.build_graph(STATE)
    assert g.nodes == ["/listener", "/rostopic_1_2", "/talker"]  # rqt_graph shows tool nodes too
    assert g.edges == [("/talker", "/listener", "/chatter"), ("/talker", "/rostopic_1_2", "/chatter")]
    t = graph.build_graph(STATE, topics_view=True)
    assert t.topics == ["/chatter"]  # /unheard is a leaf topic, /lonely a dead sink
    full = graph.build_graph(STATE, show_debug=True, topics_view=True, hide_dead_sinks=False,
                             hide_leaf_topics=False)
    assert "/rosout" in full.nodes and "/rosout" in full.topics and "/lonely" in full.topics
    dot = graph.to_dot(g)
    assert '"n__talker" -> "n__listener" [label="/chatter"];' in dot and dot.startswith("digraph graphname {")


def test_layout_svg_png() -> None:
    import cv2
    import numpy as np

    from minros.cli import graph

    g = graph.build_graph(STATE, show_debug=True, topics_view=True)
    pos, width, height = graph.layout(g)
    assert set(pos) == set(g.vertices())
    assert pos["/talker"][0] < pos["/chatter"][0] < pos["/listener"][0]  # left to right
    boxes = list(pos.values())
    for i, (x1, y1, w1, h1) in enumerate(boxes):  # no two boxes overlap
        for x2, y2, w2, h2 in boxes[i + 1:]:
            assert abs(x1 - x2) >= (w1 + w2) / 2 or abs(y1 - y2) >= (h1 + h2) / 2
    root = ET.fromstring(graph.to_svg(g))
    assert root.tag.endswith("svg")
    img = cv2.imdecode(np.frombuffer(graph.to_png(g), np.uint8), cv2.IMREAD_COLOR)
    assert img.shape[1] >= int(width) and img.shape[0] >= int(height)
    cyclic = graph.Graph()
    cyclic.nodes = ["/a", "/b"]
    cyclic.edges = [("/a", "/b", "/x"), ("/b", "/a", "/y")]
    assert set(graph.layout(cyclic)[0]) == {"/a", "/b"}


# ---------------------------------------------------------------------------------------------
# hz / bw / rosparam helpers

def test_hz_statistics() -> None:
    from minros.cli.topic_rates import HzStats, format_bw

    stats = HzStats()
    for i in range(11):
        stats.tick(100.0 + i * 0.1)
    rate, mn, mx, std, window = stats.get()
    assert rate == pytest.approx(10.0) and mn == pytest.approx(0.1) and mx == pytest.approx(0.1)
    assert std == pytest.approx(0.0, abs=1e-9) and window == 11
    assert stats.get() is None  # nothing new since the last report
    small = HzStats(window_size=3)
    for i in range(10):
        small.tick(float(i))
    assert small.get()[4] == 3
    assert format_bw([100, 100], [0.0, 1.0], 2.0) == \
        "average: 100.00B/s\n\tmean: 100.00B min: 100.00B max: 100.00B window: 2"
    assert format_bw([6_220_800] * 3, [0.0, 0.1, 0.2], 0.3).startswith("average: 62.21MB/s")


def test_rosparam_helpers() -> None:
    from minros.cli import param

    docs = param.load_documents("a: 1\n---\n_ns: sub\nb: deg(90)\n", "/base/")
    assert docs[0] == ({"a": 1}, "/base/")
    assert docs[1][1] == "/base/sub" and docs[1][0]["b"] == pytest.approx(1.5707963)
    assert param._split_set_args(["-v", "/x", "-1.5"]) == (["-v"], ["/x", "-1.5"])
    assert param._split_set_args(["-t", "f.txt", "/x"]) == (["-t", "f.txt"], ["/x"])
    text = param.dump_yaml({"b": xmlrpc.client.Binary(b"\x00\x01")})
    assert text == "b: !!binary |-\n  AAE=\n"  # Debian's rosparam crashes on Binary under Python 3
    (loaded, _ns), = param.load_documents(text, "/")
    assert isinstance(loaded["b"], xmlrpc.client.Binary) and loaded["b"].data == b"\x00\x01"
    with pytest.raises(param.ToolError, match="32-bit"):
        param._check_xmlrpc_value([1, 2 ** 40])
    with pytest.raises(param.ToolError, match="invalid YAML"):
        param.yaml_load("[1, 2")


# ---------------------------------------------------------------------------------------------
# the tools' internals as a library (rostopic.ROSTopicDelay, rosparam's YAML hooks, ...)

def test_topic_delay_and_bandwidth_meters(monkeypatch) -> None:
    from minros.cli import topic_api as topic

    now = [Time(100, 0)]
    monkeypatch.setattr(topic, "ros_now", lambda: now[0])
    delay = topic.ROSTopicDelay(window_size=-1)
    assert delay.get_delay() is None
    for i, lag in enumerate((0.5, 0.25, 0.75)):
        now[0] = Time(100 + i, 0)
        msg = PoseStamped()
        msg.header.stamp = now[0] - Duration.from_sec(lag)
        delay.callback_delay(msg)
    mean, mn, mx, _std, window = delay.get_delay()
    # the first message only starts the clock, as in rostopic
    assert (mean, mn, mx, window) == (pytest.approx(0.5), 0.25, 0.75, 3)
    assert delay.get_delay() is None  # nothing new since
    now[0] = Time(0, 0)  # simulated time restarted: the window is cleared
    delay.callback_delay(msg)
    assert delay.delays == []
    bw = topic.ROSTopicBandwidth(window_size=2)

    class Raw:
        _buff = b"x" * 10

    clock = iter([1.0, 2.0, 3.0, 4.0, 5.0])
    monkeypatch.setattr(topic.time, "time", lambda: next(clock))
    assert bw.get_bw_text() is None
    for _ in range(3):
        bw.callback(Raw())
    assert bw.sizes == [10, 10]
    # 20 bytes from t=3 to the report at t=5
    assert bw.get_bw_text() == "average: 10.00B/s\n\tmean: 10.00B min: 10.00B max: 10.00B window: 2"


def test_callback_echo_offsets_filters_and_transforms(capsys) -> None:
    from minros.cli import topic_api as topic

    String = get_message_class("std_msgs/String")
    echo = topic.CallbackEcho("/a/", None, filter_fn=lambda m: m.data != "skip",
                              value_transform_fn=topic.create_value_transform(True, False))
    echo.callback(String("skip"), {"topic": "/a"})
    echo.callback(String("abc"), {"topic": "/a"})
    assert capsys.readouterr().out == 'data: "<string length: 3>"\n---\n'
    every = topic.CallbackEcho("/a", None, echo_all_topics=True, count=1)
    every.callback(String("x"), {"topic": "/b"})
    every.callback(String("y"), {"topic": "/b"})
    assert capsys.readouterr().out == 'data: "x"\n---\n' and every.done
    sliced = topic.CallbackEcho("/p/pose/position", None)
    sliced.callback(PoseStamped(), {"topic": "/p"})
    assert capsys.readouterr().out == "x: 0.0\ny: 0.0\nz: 0.0\n---\n"
    assert topic.get_nested_attribute(PoseStamped(), "pose/position/x") == 0.0


def test_rosparam_yaml_hooks(capsys) -> None:
    import yaml

    from minros.cli import param

    class Dumper(yaml.SafeDumper):
        pass

    Dumper.add_representer(xmlrpc.client.Binary, param.represent_xml_binary)
    text = yaml.dump({"b": xmlrpc.client.Binary(b"abc")}, Dumper=Dumper)
    assert text == "b: !!binary |-\n  YWJj\n"

    class Loader(yaml.SafeLoader):
        pass

    Loader.add_constructor("!degrees", param.construct_angle_degrees)
    with pytest.raises(param.RosParamException, match="invalid degree value: x"):
        yaml.load("!degrees x", Loader=Loader)  # noqa: S506 - a SafeLoader subclass
    param.print_params({"a": {"b": 1}}, "/ns")
    assert capsys.readouterr().out == "/ns/a/b=1\n"
    assert param.load_str("x: 1", "f.yaml", default_namespace="rel") == [({"x": 1}, "rel")]


def test_rostopic_plot_helpers_and_malformed_field_patterns(capsys) -> None:
    """rostopic's _str_plot_fields/_str_plot (``-p``): a given time wins over the header's
    stamp; msgevalgen answers None (and says why) for a malformed pattern."""
    import rostopic
    from geometry_msgs.msg import PointStamped
    from minros.msgs import Time

    msg = PointStamped()
    msg.header.stamp = Time(5, 0)
    msg.point.x = 1.5
    assert rostopic._str_plot_fields(msg, "field", None) == (
        "time,field.header.seq,field.header.stamp,field.header.frame_id,"
        "field.point.x,field.point.y,field.point.z")
    assert rostopic._str_plot(msg, current_time=Time(0, 7)) == "7,0,5000000000,,1.5,0.0,0.0"
    assert rostopic._str_plot(msg) == "5000000000,0,5000000000,,1.5,0.0,0.0"
    assert rostopic.msgevalgen("/point/x")(msg) == 1.5
    assert rostopic.msgevalgen("/vals[0") is None
    assert "missing closing ']' in slice spec 'vals[0'" in capsys.readouterr().err


def test_rosmsg_overview_and_iterate_packages_over_a_given_rospack(tmp_path, capsys) -> None:
    import rospkg

    from minros.cli import msg

    assert msg.main([], prog="rosmsg") == 0
    assert "Commands:\n\trosmsg show\tShow message description\n" in capsys.readouterr().out
    pkg = tmp_path / "only_pkg"
    (pkg / "msg").mkdir(parents=True)
    (pkg / "package.xml").write_text("<package><name>only_pkg</name></package>")
    (pkg / "msg" / "A.msg").write_text("int32 a\n")
    pack = rospkg.RosPack(ros_paths=[str(tmp_path)])
    assert list(msg.iterate_packages(pack, msg.MODE_MSG)) == [("only_pkg", str(pkg / "msg"))]
    assert list(msg.iterate_packages(pack, msg.MODE_SRV)) == []
