"""``rosbag convert`` and rosbag2 reading, without processes: ROS 1 -> ROS 2 -> ROS 1 round
trips (MCAP and SQLite, Jazzy, Kilted and Humble metadata), the bytes rosbags' converter
writes, recordings other writers made, filters, types that do not convert, ``rosbag info``,
``rostopic echo -b`` and the Bag API on rosbag2, and damaged recordings (one line each).
The real ROS 2 and Debian's rosbag check the same in tests/interop/test_bag_ros2_interop.py."""

from __future__ import annotations

import json
from pathlib import Path

import pytest
import yaml

from minros.bag import Bag
from minros.bag.ros2 import msgdef
from minros.cli.bag import main as rosbag
from minros.ros2.types import registry
from ros2bag_support import (
    CUSTOM_TYPE,
    load_metadata,
    read_plain,
    rosbag2_messages,
    sample_messages,
    without_seq,
    write_sample_bag,
)

ROS2_TYPES = {
    "/camera/image": "sensor_msgs/msg/Image", "/camera/camera_info": "sensor_msgs/msg/CameraInfo",
    "/scan": "sensor_msgs/msg/LaserScan", "/odom": "nav_msgs/msg/Odometry",
    "/tf": "tf2_msgs/msg/TFMessage", "/chatter": "std_msgs/msg/String",
    "/cmd_vel": "geometry_msgs/msg/Twist", "/range": "sensor_msgs/msg/Range",
    "/status": "my_robot_msgs/msg/Status",
}


@pytest.fixture
def bag(tmp_path) -> Path:
    path = tmp_path / "in.bag"
    write_sample_bag(path)
    return path


def run(capsys, *argv: str) -> tuple:
    status = rosbag(list(argv))
    out, err = capsys.readouterr()
    return status, out, err


@pytest.mark.parametrize("storage", ["mcap", "sqlite3"])
@pytest.mark.parametrize("distro", ["jazzy", "kilted"])
def test_ros1_to_ros2_and_back(bag, tmp_path, capsys, storage, distro):
    out = tmp_path / "ros2"
    status, text, err = run(capsys, "convert", str(bag), str(out), "--to", "ros2",
                            "--storage", storage, "--distro", distro)
    assert status == 0, err
    assert err == ""
    # the plan names what ROS 2 lacks, what it adds, and what was made from the bag
    assert "/camera/image" in text and "sensor_msgs/Image" in text
    line = next(x for x in text.splitlines() if x.strip().startswith("/range "))
    assert "without header.seq" in line and "variance at its default" in line
    line = next(x for x in text.splitlines() if x.strip().startswith("/status "))
    assert "ROS 2 type made from the bag's definition" in line
    assert "Wrote" in text and "36 messages on 9 topics" in text

    meta = load_metadata(out)
    assert meta["version"] == 9 and meta["ros_distro"] == distro
    assert meta["storage_identifier"] == storage and meta["message_count"] == 36
    reg = registry(distro)
    topics = {t["topic_metadata"]["name"]: t for t in meta["topics_with_message_count"]}
    assert set(topics) == set(ROS2_TYPES)
    stored = rosbag2_messages(out)
    for topic, entry in topics.items():
        tm = entry["topic_metadata"]
        assert tm["type"] == ROS2_TYPES[topic] and tm["serialization_format"] == "cdr"
        assert entry["message_count"] == 4
        if topic != "/status":
            assert tm["type_description_hash"] == reg.type_hash(tm["type"]), topic
        assert stored[topic][1] == tm["type_description_hash"]
    # a latched ROS 1 topic is transient local in ROS 2
    qos = topics["/camera/camera_info"]["topic_metadata"]["offered_qos_profiles"]
    assert qos[0]["durability"] == "transient_local" and qos[0]["reliability"] == "reliable"
    assert topics["/scan"]["topic_metadata"]["offered_qos_profiles"] == []
    # every CDR message decodes with minros's codec to what the ROS 1 message said
    for (topic, msg, _t), data in zip(sample_messages(), _in_order(stored)):
        decoded = reg.codec(ROS2_TYPES[topic]).deserialize(data) if topic != "/status" else None
        if topic == "/camera/camera_info":
            assert list(decoded.d) == list(msg.D) and list(decoded.k) == list(msg.K)
            assert decoded.header.stamp.sec == msg.header.stamp.secs
        if topic == "/scan":
            assert list(decoded.ranges) == pytest.approx(list(msg.ranges))

    back = tmp_path / "back.bag"
    status, text, err = run(capsys, "convert", str(out), str(back))
    assert status == 0, err
    assert "header.seq counted from 1" in text and "without variance" in text
    before, after = read_plain(bag), read_plain(back)
    assert set(before) == set(after)
    for topic in before:
        assert [(t, typ) for t, typ, _v in after[topic]] == \
            [(t, typ) for t, typ, _v in before[topic]]
        assert [without_seq(v) for _t, _typ, v in after[topic]] == \
            [without_seq(v) for _t, _typ, v in before[topic]], topic
        if "header" in before[topic][0][2]:
            assert [v["header"]["seq"] for _t, _typ, v in after[topic]] == [1, 2, 3, 4]
    with Bag(str(bag)) as a, Bag(str(back)) as b:
        conns_a = {c.topic: c for c in a._connections.values()}
        conns_b = {c.topic: c for c in b._connections.values()}
        for topic, c in conns_a.items():  # the ROS 1 types come back exactly
            d = conns_b[topic]
            assert (d.datatype, d.md5sum, d.msg_def) == (c.datatype, c.md5sum, c.msg_def)
            assert (d.callerid, d.latching) == (c.callerid, c.latching)


def _in_order(stored):
    """The CDR messages of a converted sample bag in sample_messages()'s order."""
    queues = {topic: list(entry[2]) for topic, entry in stored.items()}
    for topic, _msg, _t in sample_messages():
        yield queues[topic].pop(0)


def test_humble_writes_rosbag2_humbles_metadata(bag, tmp_path, capsys):
    out = tmp_path / "humble"
    status, _text, err = run(capsys, "convert", str(bag), str(out), "--distro", "humble", "-q")
    assert status == 0, err
    meta = load_metadata(out)
    assert meta["version"] == 5
    assert "ros_distro" not in meta
    for entry in meta["topics_with_message_count"]:
        tm = entry["topic_metadata"]
        assert "type_description_hash" not in tm
        assert isinstance(tm["offered_qos_profiles"], str)  # Humble's YAML string
    latched = next(t for t in meta["topics_with_message_count"]
                   if t["topic_metadata"]["name"] == "/camera/camera_info")
    assert yaml.safe_load(latched["topic_metadata"]["offered_qos_profiles"])[0]["durability"] == 1
    # read back (as Humble: the recording has no hashes), values as before
    with Bag(str(out)) as b:
        assert "read as ROS 2 humble" in b.version
    assert {k: [without_seq(v) for *_x, v in vs] for k, vs in read_plain(out).items()} == \
        {k: [without_seq(v) for *_x, v in vs] for k, vs in read_plain(bag).items()}


def test_cdr_bytes_equal_rosbags_converters(bag, tmp_path):
    """rosbags' own converter (rosbags-convert's function, run in this process) writes the same
    CDR bytes for every type its typestore knows; the type it copies from the bag differs only
    in field-name case (ROS 2 requires lower case: ours says name, theirs Name)."""
    from rosbags.convert.converter import convert
    from rosbags.typesys import Stores, get_typestore

    ours, theirs = tmp_path / "ours", tmp_path / "theirs"
    assert rosbag(["convert", "-q", str(bag), str(ours)]) == 0
    convert([bag], theirs, "mcap", 9, None, "file", None, get_typestore(Stores.ROS2_JAZZY), [], [],
            [], [])
    a, b = rosbag2_messages(ours), rosbag2_messages(theirs)
    assert set(a) == set(b)
    for topic in a:
        assert a[topic][0] == b[topic][0], topic
        assert a[topic][2] == b[topic][2], topic  # byte for byte
        if topic != "/status":
            assert a[topic][1] == b[topic][1], topic  # the same type hash
    # and minros reads rosbags' recording, its Name-cased custom type included, as the bag
    assert {k: [without_seq(v) for *_x, v in vs] for k, vs in read_plain(theirs).items()} == \
        {k: [without_seq(v) for *_x, v in vs] for k, vs in read_plain(bag).items()}


def test_stored_definitions_are_rosbag2s_layout(bag, tmp_path):
    from rosbags.rosbag2 import Reader

    out = tmp_path / "ros2"
    assert rosbag(["convert", "-q", str(bag), str(out)]) == 0
    with Reader(out) as reader:
        defs = {c.msgtype: c.msgdef.data for c in reader.connections}
    odom = defs["nav_msgs/msg/Odometry"]
    assert odom.startswith(registry().message("nav_msgs/msg/Odometry").text)
    names = [b[0] for b in msgdef.split("nav_msgs/msg/Odometry", odom)]
    assert names == ["nav_msgs/msg/Odometry", "geometry_msgs/msg/PoseWithCovariance",
                     "geometry_msgs/msg/Pose", "geometry_msgs/msg/Point",
                     "geometry_msgs/msg/Quaternion", "geometry_msgs/msg/TwistWithCovariance",
                     "geometry_msgs/msg/Twist", "geometry_msgs/msg/Vector3",
                     "std_msgs/msg/Header", "builtin_interfaces/msg/Time"]
    assert "\n" + "=" * 80 + "\nMSG: geometry_msgs/PoseWithCovariance\n" in odom
    status = defs["my_robot_msgs/msg/Status"]
    assert "string name\n" in status and "MSG: my_robot_msgs/Wheel\n" in status
    with pytest.raises(msgdef.DefinitionError, match="IDL"):
        msgdef.split("a/msg/B", "=" * 80 + "\nIDL: a/msg/B\nmodule a {};\n")


def test_topic_and_exclude_select_by_topic_or_type(bag, tmp_path, capsys):
    out = tmp_path / "some"
    status, _text, err = run(capsys, "convert", "-q", str(bag), str(out), "--topic", "/camera/*",
                             "--topic", "nav_msgs/Odometry", "--topic", "tf2_msgs/msg/TFMessage",
                             "--exclude", "sensor_msgs/Image")
    assert status == 0, err
    names = {t["topic_metadata"]["name"] for t in load_metadata(out)["topics_with_message_count"]}
    assert names == {"/camera/camera_info", "/odom", "/tf"}
    back = tmp_path / "back.bag"
    assert rosbag(["convert", "-q", str(out), str(back), "--exclude", "/odom"]) == 0
    assert set(read_plain(back)) == {"/camera/camera_info", "/tf"}
    status, _text, err = run(capsys, "convert", str(bag), str(tmp_path / "none"), "--topic",
                             "/nothing")
    assert status == 1 and err == f"ERROR: no topic of {bag} is selected\n"
    assert not (tmp_path / "none").exists()


def test_a_type_that_cannot_map_is_named_and_the_rest_goes_on(tmp_path, capsys):
    import minros
    from minros.msgs import generate_dynamic
    from std_msgs.msg import String

    Clash = generate_dynamic("clash_msgs/Twice", "int32 speed\nint32 Speed\n")["clash_msgs/Twice"]
    path = tmp_path / "clash.bag"
    with Bag(str(path), "w") as b:
        b.write("/clash", Clash(speed=1, Speed=2), minros.Time(5, 0))
        b.write("/chatter", String("still here"), minros.Time(5, 1))
    out = tmp_path / "out"
    status, text, err = run(capsys, "convert", str(path), str(out))
    assert status == 0
    assert err.count("\n") == 1 and err.startswith("WARNING: /clash [clash_msgs/Twice] is not "
                                                   "converted: ")
    assert "speed" in err and "--exclude /clash" in err
    assert "1 messages on 1 topics" in text
    assert [v for *_x, v in read_plain(out)["/chatter"]] == [{"data": "still here"}]


def test_info_echo_and_the_bag_api_read_rosbag2(bag, tmp_path, capsys):
    out = tmp_path / "rec"
    assert rosbag(["convert", "-q", str(bag), str(out)]) == 0
    status, text, err = run(capsys, "info", str(out))
    assert status == 0, err
    assert "version:     rosbag2 9 (mcap, cdr; read as ROS 2 jazzy)" in text
    assert "messages:    36" in text
    assert "sensor_msgs/CameraInfo [c9a58c1b0b154e0e6da7578cb991d214]" in text
    assert "/scan" in text and "4 msgs" in text
    reg = registry()
    assert f"sensor_msgs/msg/Image      [{reg.type_hash('sensor_msgs/msg/Image')}]" in text
    status, text, _err = run(capsys, "info", "-y", str(out))
    info = yaml.safe_load(text)
    assert info["messages"] == 36
    assert {"type": "nav_msgs/msg/Odometry", "type_hash": reg.type_hash("nav_msgs/msg/Odometry")} \
        in info["ros2_types"]
    # the storage file on its own reads too (no metadata.yaml: no custom_data, the types by
    # the rules; the custom one made from the stored ROS 2 definition, lower-case names)
    with Bag(str(out / "rec.mcap")) as b:
        msgs = {topic: msg for topic, msg, _t in b.read_messages()}
    assert msgs["/camera/camera_info"].D == pytest.approx([0.3, -0.2, 0.001, 0.0, 0.0])
    assert msgs["/status"].name == "robot3" and msgs["/status"].wheels[1].speed == -0.25
    from minros.cli.topic import main as rostopic

    assert rostopic(["echo", "-b", str(out), "-n", "1", "/odom/pose/pose/position"]) == 0
    text = capsys.readouterr().out
    assert text == "x: 0.0\ny: 0.0\nz: 0.0\n---\n"
    # a topic that does not read as ROS 1 is named with the reason
    meta = out / "metadata.yaml"
    meta.write_text(meta.read_text().replace("type: std_msgs/msg/String",
                                             "type: nowhere_msgs/msg/Gone"))
    assert rostopic(["echo", "-b", str(out), "/chatter"]) == 1
    err = capsys.readouterr().err
    assert "/chatter [nowhere_msgs/msg/Gone]" in err and "does not read as ROS 1" in err


def test_rosbag2_from_another_writer_with_its_own_custom_type(tmp_path, capsys):
    """A recording as rclpy-side tools write it (rosbags' Writer, types from the stored
    definitions only): a type minros has never seen reads through its stored definition."""
    from rosbags.rosbag2 import Writer
    from rosbags.typesys import Stores, get_types_from_msg, get_typestore

    store = get_typestore(Stores.ROS2_JAZZY)
    store.register(get_types_from_msg("int32 count\nstring[] labels\ngeometry_msgs/Point where\n",
                                      "fresh_msgs/msg/Counted"))
    Counted = store.types["fresh_msgs/msg/Counted"]
    Point = store.types["geometry_msgs/msg/Point"]
    out = tmp_path / "theirs"
    with Writer(out, version=9) as writer:
        conn = writer.add_connection("/counted", "fresh_msgs/msg/Counted", typestore=store)
        for i in range(3):
            msg = Counted(count=i, labels=["a", "b"][:i], where=Point(x=1.0, y=2.0, z=float(i)))
            writer.write(conn, 10**9 * (i + 1), store.serialize_cdr(msg, "fresh_msgs/msg/Counted"))
    with Bag(str(out)) as b:
        got = [(m._type, m.count, list(m.labels), m.where.z) for _t, m, _s in b.read_messages()]
    assert got == [("fresh_msgs/Counted", 0, [], 0.0), ("fresh_msgs/Counted", 1, ["a"], 1.0),
                   ("fresh_msgs/Counted", 2, ["a", "b"], 2.0)]
    status, text, err = run(capsys, "info", str(out))
    assert status == 0 and "fresh_msgs/msg/Counted" in text


# -- damaged recordings: one line naming the file and what is wrong -------------------------------

def _recording(bag: Path, tmp_path: Path, storage: str = "mcap") -> Path:
    out = tmp_path / f"rec-{storage}"
    assert rosbag(["convert", "-q", str(bag), str(out), "--storage", storage]) == 0
    return out


def _one_line(capsys, argv, expected: str) -> None:
    status = rosbag(argv)
    out, err = capsys.readouterr()
    assert status == 1, (out, err)
    assert err.count("\n") == 1 and "Traceback" not in err, err
    assert expected in err, err


@pytest.mark.parametrize("command", ["info", "convert"])
def test_damaged_recordings_give_one_line(bag, tmp_path, capsys, command):
    def argv(path):
        return ["info", str(path)] if command == "info" else \
            ["convert", str(path), str(tmp_path / "out.bag"), "--force"]

    rec = _recording(bag, tmp_path)
    meta = rec / "metadata.yaml"
    good = meta.read_text()
    meta.write_text(good.replace("  storage_identifier: mcap\n", "  storage_identifier: [mcap\n"))
    _one_line(capsys, argv(rec), f"{meta} is not valid YAML (")
    meta.write_text(good.replace("  message_count: 36\n", ""))
    _one_line(capsys, argv(rec), f"{meta}: rosbag2_bagfile_information.message_count is missing")
    meta.write_text(good.replace("version: 9", "version: 12"))
    _one_line(capsys, argv(rec), f"{meta}: metadata version 12 is newer than minros reads")
    meta.write_text("just text\n")
    _one_line(capsys, argv(rec), f"{meta} is not rosbag2 metadata")
    meta.unlink()
    _one_line(capsys, argv(rec), f"{meta} is missing: {rec} is not a rosbag2 recording, or its "
                                 f"recorder did not finish: read its storage file on its own "
                                 f"instead (rosbag info {rec / 'rec-mcap.mcap'})")
    meta.write_text(good)
    mcap = rec / "rec-mcap.mcap"
    data = mcap.read_bytes()
    mcap.write_bytes(data[:len(data) // 2])
    _one_line(capsys, argv(rec), f"{mcap} is cut short: it ends after {len(data) // 2} bytes "
                                 f"without MCAP's footer")
    _one_line(capsys, argv(mcap), f"{mcap} is cut short")
    mcap.write_bytes(b"")
    _one_line(capsys, argv(rec), f"{mcap} is empty")
    mcap.unlink()
    _one_line(capsys, argv(rec), f"{mcap} is missing ({meta} lists it")

    db = _recording(bag, tmp_path, "sqlite3")
    db3 = db / "rec-sqlite3.db3"
    db3.unlink()
    _one_line(capsys, argv(db), f"{db3} is missing ({db / 'metadata.yaml'} lists it")
    db3.write_bytes(b"not a database at all, not at all")
    _one_line(capsys, argv(db), f"{db3} is not an SQLite database")


def _first_message_length_spoilt(data: bytearray) -> bytearray:
    """``data`` (an MCAP file) with the length of the first message in its first chunk made
    far larger than the chunk."""
    import struct

    pos = 8
    while data[pos] != 0x06:  # records: op, uint64 length, body
        pos += 9 + struct.unpack_from("<Q", data, pos + 1)[0]
    body = pos + 9
    (clen,) = struct.unpack_from("<I", data, body + 28)  # compression name
    rec = body + 32 + clen + 8
    while data[rec] != 0x05:
        rec += 9 + struct.unpack_from("<Q", data, rec + 1)[0]
    struct.pack_into("<Q", data, rec + 1, 2**40)
    return data


def test_damage_inside_an_mcap_chunk_names_the_file(bag, tmp_path, capsys):
    rec = _recording(bag, tmp_path)
    mcap = rec / "rec-mcap.mcap"
    data = bytearray(mcap.read_bytes())
    mcap.write_bytes(bytes(_first_message_length_spoilt(data)))
    status = rosbag(["convert", str(rec), str(tmp_path / "out.bag")])
    out, err = capsys.readouterr()
    assert status == 1 and err.count("\n") == 1, err
    assert f"{mcap} is damaged:" in err
    assert not (tmp_path / "out.bag").exists()


def test_convert_usage(bag, tmp_path, capsys):
    assert rosbag(["convert", str(bag)]) == 2
    assert "You must specify an output bag." in capsys.readouterr().err
    (tmp_path / "taken").mkdir()
    status, _text, err = run(capsys, "convert", str(bag), str(tmp_path / "taken"))
    assert status == 1 and "exists already: remove it, give another output name, or pass " \
                           "--force" in err
    (tmp_path / "taken" / "notes.txt").write_text("mine")
    status, _text, err = run(capsys, "convert", str(bag), str(tmp_path / "taken"), "--force")
    assert status == 1 and "is a directory that is not a ROS 2 recording" in err
    assert (tmp_path / "taken" / "notes.txt").exists()
    assert rosbag(["convert", "-q", str(bag), str(tmp_path / "rec")]) == 0
    assert rosbag(["convert", "-q", "--force", "--topic", "/odom", str(bag),
                   str(tmp_path / "rec")]) == 0
    assert load_metadata(tmp_path / "rec")["message_count"] == 4
    status, _text, err = run(capsys, "convert", str(bag), str(tmp_path / "x.txt"), "--to", "ros1")
    assert status == 1 and "must end in .bag (or .mcap for ROS 1 MCAP)" in err
    status, _text, err = run(capsys, "convert", str(bag), str(tmp_path / "x.bag"), "--to", "ros1")
    assert status == 1 and err == f"ERROR reading {bag}: {bag} is not a ROS 2 recording (a " \
                                  "rosbag2 directory, a ROS 2 .mcap or a .db3 file): convert a " \
                                  "ROS 1 bag with --to ros2\n"
    status, _text, err = run(capsys, "convert", str(tmp_path / "nope.bag"), str(tmp_path / "o"))
    assert status == 1 and err == f"ERROR reading {tmp_path / 'nope.bag'}: no such file or " \
                                  "directory\n"
    status, text, _err = run(capsys, "help", "convert")
    assert status == 0 and "--storage=mcap|sqlite3" in text and "--distro" in text
    status, text, _err = run(capsys, "help")
    assert "   convert  \tConvert a bag to a ROS 2 recording" in text


def test_messages_a_converter_rejects_are_counted_and_left_out(tmp_path, capsys):
    """A ROS 1 message that does not match its definition (cut short in the bag) is left out
    and counted; the others are converted."""
    import minros
    from std_msgs.msg import String

    path = tmp_path / "short.bag"
    with Bag(str(path), "w") as b:
        b.write("/chatter", String("whole"), minros.Time(1, 0))
        b.write("/chatter", ("std_msgs/String", b"\x09\x00\x00\x00abc", String._md5sum, String),
                minros.Time(2, 0), raw=True)
        b.write("/chatter", String("whole again"), minros.Time(3, 0))
    status, text, err = run(capsys, "convert", str(path), str(tmp_path / "out"))
    assert status == 0
    assert err.startswith("WARNING: 1 message(s) of /chatter [std_msgs/String] did not convert "
                          "and were left out (the first at 2.000000000: ")
    assert [v["data"] for *_x, v in read_plain(tmp_path / "out")["/chatter"]] == \
        ["whole", "whole again"]


def test_custom_data_keeps_only_what_converting_back_needs(bag, tmp_path):
    out = tmp_path / "rec"
    assert rosbag(["convert", "-q", str(bag), str(out)]) == 0
    stash = json.loads(load_metadata(out)["custom_data"]["minros.ros1"])
    assert stash["topics"]["/camera/camera_info"] == {
        "type": "sensor_msgs/CameraInfo", "ros2_type": "sensor_msgs/msg/CameraInfo",
        "callerid": "/camera_node", "latching": "1"}
    # installed types by md5 sum only; the custom type with its definition
    assert stash["types"]["sensor_msgs/Image"] == {"md5sum": "060021388200f6f0f447d0fcd9c64743"}
    assert stash["types"][CUSTOM_TYPE]["message_definition"].startswith("# the status")
    # a damaged stash: the ROS 2 rules decide, with a warning
    meta = out / "metadata.yaml"
    data = yaml.safe_load(meta.read_text())
    info = data["rosbag2_bagfile_information"]
    info["custom_data"]["minros.ros1"] = info["custom_data"]["minros.ros1"].replace('"topics"',
                                                                                    '"ropics"')
    meta.write_text(yaml.safe_dump(data))
    with Bag(str(out)) as b:
        assert any("custom_data minros.ros1 is damaged" in w for w in b._reader.warnings)
        assert {m._type for _t, m, _s in b.read_messages(topics=["/status"])} == \
            {"my_robot_msgs/Status"}


def test_a_recording_converted_twice_is_the_same(bag, tmp_path):
    """Conversion is deterministic: the same bag gives the same metadata and bytes."""
    a, b = tmp_path / "a", tmp_path / "b"
    for out in (a, b):
        assert rosbag(["convert", "-q", str(bag), str(out)]) == 0
    assert load_metadata(a)["topics_with_message_count"] == \
        load_metadata(b)["topics_with_message_count"]
    assert rosbag2_messages(a) == rosbag2_messages(b)


def test_the_mcap_file_reads_with_the_mcap_library_and_rosbags(tmp_path):
    """minros's MCAP storage writer (one copy per message): several chunks, message indexes,
    the summary and rosbag2's metadata record, read by foxglove's mcap library (indexed, in
    time order, by topic) and by rosbags (a time window)."""
    from mcap.reader import make_reader
    from rosbags.rosbag2 import Reader

    import minros
    from sensor_msgs.msg import Image
    from std_msgs.msg import String

    path = tmp_path / "big.bag"
    with Bag(str(path), "w") as b:
        for i in range(12):  # 12 x 400 KB images: five chunks
            img = Image(height=400, width=1000, encoding="mono8", step=1000,
                        data=bytes([i]) * 400_000)
            b.write("/image", img, minros.Time(100 + i, 0))
            b.write("/words", String(f"w{i}"), minros.Time(100 + i, 500))
    out = tmp_path / "big"
    assert rosbag(["convert", "-q", str(path), str(out)]) == 0
    mcap = out / "big.mcap"
    with open(mcap, "rb") as f:
        reader = make_reader(f)
        summary = reader.get_summary()
        assert summary.statistics.message_count == 24 and len(summary.chunk_indexes) >= 4
        assert summary.statistics.message_start_time == 100 * 10**9
        assert summary.statistics.message_end_time == 111 * 10**9 + 500
        assert {s.name for s in summary.schemas.values()} == {"sensor_msgs/msg/Image",
                                                              "std_msgs/msg/String"}
        got = [(ch.topic, m.log_time, len(m.data)) for _s, ch, m in
               reader.iter_messages(log_time_order=True)]
        words = [m.data for _s, _c, m in reader.iter_messages(topics=["/words"])]
        (meta,) = list(reader.iter_metadata())
    assert [t for _topic, t, _n in got] == sorted(t for _topic, t, _n in got)
    assert len(got) == 24 and all(n > 400_000 for topic, _t, n in got if topic == "/image")
    assert len(words) == 12 and words[3].endswith(b"w3\x00")
    assert meta.name == "rosbag2"
    assert yaml.safe_load(meta.metadata["serialized_metadata"])["message_count"] == 24
    with Reader(out) as r:
        window = [(c.topic, t) for c, t, _d in r.messages(start=103 * 10**9, stop=105 * 10**9)]
    assert window == [("/image", 103 * 10**9), ("/words", 103 * 10**9 + 500),
                      ("/image", 104 * 10**9), ("/words", 104 * 10**9 + 500)]
