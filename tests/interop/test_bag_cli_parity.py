"""The rosbag file commands and the bag options of rostopic/rosmsg, minros beside Debian's, on
the same files: same output, same exit status (no master needed)."""

from __future__ import annotations

import os
import subprocess
from pathlib import Path

import pytest

from support import PYTHON, REFERENCE_PYTHON, reference_env, require_reference

pytestmark = pytest.mark.interop

MAKE_BAG = r'''
import sys
import rospy
from rosbag import Bag
from std_msgs.msg import String, Int32
from geometry_msgs.msg import PointStamped
with Bag(sys.argv[1], "w", chunk_threshold=4000) as b:
    for i in range(200):
        t = rospy.Time(1000 + i // 20, (i % 20) * 50000000)
        b.write("/words", String("w%d" % i), t)
        if i % 4 == 0:
            p = PointStamped()
            p.header.stamp = t
            p.header.frame_id = "map"
            p.point.x = i / 4.0
            b.write("/points", p, t)
        if i % 50 == 0:
            b.write("/count", Int32(i), t)
'''


def _run(minros: bool, *argv: str, cwd: Path, timeout: float = 60) -> subprocess.CompletedProcess:
    """minros's ``rosTOOL ...`` console script or Debian's (TOOL: bag, topic, msg)."""
    env = dict(os.environ, TZ="UTC")
    if minros:
        cmd = [str(Path(PYTHON).parent / f"ros{argv[0]}"), *argv[1:]]
    else:
        cmd, env = [f"/usr/bin/ros{argv[0]}", *argv[1:]], reference_env(env)
    return subprocess.run(cmd, env=env, cwd=cwd, capture_output=True, text=True, timeout=timeout)


def both(tmp_path: Path, *argv: str) -> tuple:
    ours = _run(True, *argv, cwd=tmp_path)
    theirs = _run(False, *argv, cwd=tmp_path)
    return ours, theirs


@pytest.fixture
def bagdir(tmp_path: Path) -> Path:
    require_reference()
    script = tmp_path / "make.py"
    script.write_text(MAKE_BAG)
    made = subprocess.run([REFERENCE_PYTHON, str(script), str(tmp_path / "deb.bag")],
                          env=reference_env({}), capture_output=True, text=True, timeout=60)
    assert made.returncode == 0, made.stderr
    made = subprocess.run([PYTHON, str(script), str(tmp_path / "ours.bag")], capture_output=True,
                          text=True, timeout=60)
    assert made.returncode == 0, made.stderr
    return tmp_path


@pytest.mark.parametrize("bag", ["deb.bag", "ours.bag"])
@pytest.mark.parametrize("args", [["info"], ["info", "--freq"], ["info", "-y"],
                                  ["info", "-y", "-k", "topics"], ["info", "-y", "-k", "duration"]])
def test_info_same_output(bagdir, bag, args):
    ours, theirs = both(bagdir, "bag", *args, bag)
    assert (ours.returncode, ours.stdout) == (theirs.returncode, theirs.stdout)


@pytest.mark.parametrize("argv", [
    ["topic", "echo", "-b", "deb.bag", "/points"],
    ["topic", "echo", "-b", "ours.bag", "-n", "3", "/words"],
    ["topic", "echo", "-b", "deb.bag", "/points/point/x"],
    ["topic", "echo", "-b", "ours.bag", "-a", "-n", "5"],
    ["topic", "echo", "-b", "deb.bag", "-p", "/count"],
    ["topic", "list", "-b", "deb.bag"],
    ["topic", "list", "-b", "ours.bag", "/points"],
    ["msg", "show", "-b", "deb.bag", "geometry_msgs/PointStamped"],
    ["msg", "show", "-r", "-b", "ours.bag", "std_msgs/String"],
    ["topic", "echo", "-b", "missing.bag", "/x"],
])
def test_bag_options_of_rostopic_and_rosmsg(bagdir, argv):
    ours, theirs = both(bagdir, *argv)
    assert ours.returncode == theirs.returncode, (ours.stderr, theirs.stderr)
    assert ours.stdout == theirs.stdout
    if theirs.returncode:
        assert ours.stderr.strip().splitlines()[-1] == theirs.stderr.strip().splitlines()[-1]


def _messages(python: str, path: Path) -> list:
    code = ("import sys, rosbag\n"
            "for t, m, s in rosbag.Bag(sys.argv[1]).read_messages():\n"
            "    print(t, s.to_nsec(), repr(m).replace(chr(10), ' '))\n")
    env = reference_env({}) if python == REFERENCE_PYTHON else None
    out = subprocess.run([python, "-c", code, str(path)], env=env, capture_output=True, text=True, timeout=60)
    assert out.returncode == 0, out.stderr
    return out.stdout.splitlines()


def test_filter_like_debian(bagdir):
    expr = "topic == '/points' and m.point.x > 10 or topic == '/count'"
    ours = _run(True, "bag", "filter", "ours.bag", "f-ours.bag", expr, cwd=bagdir)
    theirs = _run(False, "bag", "filter", "deb.bag", "f-deb.bag", expr, cwd=bagdir)
    assert ours.returncode == theirs.returncode == 0, (ours.stderr, theirs.stderr)
    assert "f-ours.bag" in ours.stdout and "100%" in ours.stdout  # rosbag's progress bar
    read_by_debian = _messages(REFERENCE_PYTHON, bagdir / "f-ours.bag")
    assert read_by_debian == _messages(REFERENCE_PYTHON, bagdir / "f-deb.bag")
    assert len(read_by_debian) == 4 + 39
    for argv, status in ((["filter", "nothere.bag", "o.bag", "True"], 2),
                         (["filter", "ours.bag", "ours.bag", "True"], 3),
                         (["filter", "ours.bag"], 2)):
        ours, theirs = both(bagdir, "bag", *argv)
        assert ours.returncode == theirs.returncode == status
        assert ours.stderr.strip().splitlines()[-1] == theirs.stderr.strip().splitlines()[-1]


@pytest.mark.parametrize("flag,name", [(None, "bz2"), ("--lz4", "lz4")])
def test_compress_decompress_like_debian(bagdir, flag, name):
    before = _messages(REFERENCE_PYTHON, bagdir / "deb.bag")
    ours = _run(True, "bag", "compress", *([flag] if flag else []), "deb.bag", cwd=bagdir)
    assert ours.returncode == 0, ours.stderr
    assert (bagdir / "deb.orig.bag").exists()
    info = _run(False, "bag", "info", "-y", "-k", "compression", "deb.bag", cwd=bagdir)
    assert info.stdout.strip() == name
    assert _messages(REFERENCE_PYTHON, bagdir / "deb.bag") == before
    again = both(bagdir, "bag", "compress", "deb.bag")
    assert [r.stderr.strip() for r in again] == ["Skipping deb.bag. Backup path deb.orig.bag already exists."] * 2
    ours = _run(True, "bag", "decompress", "-f", "deb.bag", cwd=bagdir)
    assert ours.returncode == 0, ours.stderr
    info = _run(False, "bag", "info", "-y", "-k", "compression", "deb.bag", cwd=bagdir)
    assert info.stdout.strip() == "none"
    assert _messages(PYTHON, bagdir / "deb.bag") == _messages(REFERENCE_PYTHON, bagdir / "deb.bag") == before


def test_check_and_usage_like_debian(bagdir):
    ours, theirs = both(bagdir, "bag", "check", "deb.bag")
    assert (ours.returncode, ours.stdout) == (theirs.returncode, theirs.stdout)
    assert ours.stdout == "Bag file does not need any migrations.\n"
    for argv in (["bag"], ["bag", "record", "-h"], ["bag", "play", "-h"], ["bag", "info", "-h"],
                 ["bag", "filter", "-h"], ["bag", "reindex", "-h"], ["bag", "compress", "-h"],
                 ["bag", "record"], ["bag", "play"], ["bag", "info"], ["bag", "info", "-k", "x", "a.bag"],
                 ["bag", "record", "-o", "a", "-O", "b", "/x"], ["bag", "record", "--split", "/x"]):
        ours, theirs = both(bagdir, *argv)
        if argv == ["bag"]:  # the list of commands: Debian's but encrypt and decrypt, and
            # minros's convert (ROS 1 bags <-> ROS 2 recordings)
            theirs.stdout = "".join(line for line in theirs.stdout.splitlines(keepends=True)
                                    if not line.startswith(("   encrypt  ", "   decrypt  ")))
            assert "   convert  \tConvert a bag to a ROS 2 recording" in ours.stdout
            ours.stdout = "".join(line for line in ours.stdout.splitlines(keepends=True)
                                  if not line.startswith("   convert  "))
        assert (ours.returncode, ours.stdout, ours.stderr) == (theirs.returncode, theirs.stdout, theirs.stderr), argv


# a bag recorded under older definitions: std_msgs/ColorRGBA without its alpha, alone and
# inside visualization_msgs/Marker (so that Marker's md5 sum differs too), and a current type
OLD_BAG = r'''
import io, sys
from minros.bag import Bag
from minros.msgs import Time, generate_dynamic, get_message_class
marker = get_message_class("visualization_msgs/Marker")
old_marker_text = marker._full_text.replace("float32 r\nfloat32 g\nfloat32 b\nfloat32 a",
                                            "float32 r\nfloat32 g\nfloat32 b")
color_text = "float32 r\nfloat32 g\nfloat32 b\n"
OldMarker = generate_dynamic(marker._type, old_marker_text)[marker._type]
OldColor = generate_dynamic("std_msgs/ColorRGBA", color_text)["std_msgs/ColorRGBA"]
String = get_message_class("std_msgs/String")

def write(bag, topic, m, text, t):
    buff = io.BytesIO()
    m.serialize(buff)
    bag.write(topic, (m._type, buff.getvalue(), m._md5sum, None, type(m)), t, raw=True,
              connection_header={"type": m._type, "md5sum": m._md5sum, "topic": topic,
                                 "message_definition": text, "callerid": "/old"})

with Bag(sys.argv[1], "w") as bag:
    for i in range(3):
        t = Time(10 + i, 0)
        write(bag, "/color", OldColor(r=0.25 * i, g=0.5, b=1.0), color_text, t)
        m = OldMarker(ns="n", id=i)
        m.color.r = 0.25
        m.colors = [OldColor(r=1.0, g=0.0, b=0.5)] * (i + 1)
        write(bag, "/marker", m, old_marker_text, t)
        bag.write("/chatter", String(data="hi %d" % i), t)
'''

READ_BAG = r'''
import json, sys, rosbag
out = []
with rosbag.Bag(sys.argv[1]) as b:
    for topic, m, t in b.read_messages():
        colors = [[c.r, c.g, c.b, c.a] for c in getattr(m, "colors", [])]
        color = getattr(m, "color", m if m._type == "std_msgs/ColorRGBA" else None)
        out.append([topic, m._type, m._md5sum, t.to_nsec(), getattr(m, "data", None), colors,
                    [color.r, color.g, color.b, color.a] if color is not None else None])
print(json.dumps(out))
'''


def _classes(text: str) -> set:
    """The rule classes of a rule file (Debian's check writes a rule once per path needing it)."""
    return {"class " + block for block in text.split("class ")[1:]}


def test_check_and_fix_migrate_old_definitions_like_debian(tmp_path):
    """rosbag check lists the migrations an old bag needs and the rules missing, -g writes
    the rules to complete (the same text as Debian's), and once completed, check says the bag
    is ready and fix writes the bag Debian's fix writes."""
    require_reference()
    made = subprocess.run([PYTHON, "-c", OLD_BAG, str(tmp_path / "old.bag")], capture_output=True,
                          text=True, timeout=60)
    assert made.returncode == 0, made.stderr
    ours, theirs = both(tmp_path, "bag", "check", "-n", "old.bag")
    assert (ours.returncode, ours.stdout, ours.stderr) == (theirs.returncode, theirs.stdout, theirs.stderr)
    assert "To generate rules, please run with -g <rulefile>" in ours.stdout
    assert ours.stdout.count("1 rules missing:") == 2  # ColorRGBA, and Marker through it
    for minros, name in ((True, "ours.bmr"), (False, "debian.bmr")):
        run = _run(minros, "bag", "check", "old.bag", "-n", "-g", name, cwd=tmp_path)
        assert run.returncode == 0, run.stderr
        assert run.stdout.endswith(f"\nThe necessary rule files have been written to: {name}\n")
    ours, theirs = both(tmp_path, "bag", "check", "old.bag", "-n", "-g", "ours.bmr")
    assert (ours.returncode, ours.stderr) == (theirs.returncode, theirs.stderr) == (2, theirs.stderr)
    rules, debian_rules = (tmp_path / "ours.bmr").read_text(), (tmp_path / "debian.bmr").read_text()
    assert _classes(rules) == _classes(debian_rules) and len(_classes(rules)) == 1
    assert "#No matching field name in old message\n\t\tnew_msg.a = 0.\n" in rules
    # a person completes the rule: alpha 1, and valid
    (tmp_path / "done.bmr").write_text(rules.replace("valid = False", "valid = True")
                                       .replace("new_msg.a = 0.", "new_msg.a = 1.0"))
    ours, theirs = both(tmp_path, "bag", "check", "-n", "old.bag", "done.bmr")
    assert (ours.returncode, ours.stdout) == (theirs.returncode, theirs.stdout)
    assert ours.stdout.endswith("\nAll rules defined.  Bag is ready to be migrated\n")
    fixed = {}
    for minros, name in ((True, "fixed-ours.bag"), (False, "fixed-debian.bag")):
        run = _run(minros, "bag", "fix", "-n", "old.bag", name, "done.bmr", cwd=tmp_path)
        assert (run.returncode, run.stdout) == (0, "Bag migrated successfully.\n"), run.stderr
        read = subprocess.run([REFERENCE_PYTHON, "-c", READ_BAG, str(tmp_path / name)],
                              env=reference_env({}), capture_output=True, text=True, timeout=60)
        assert read.returncode == 0, read.stderr
        fixed[name] = read.stdout
    assert fixed["fixed-ours.bag"] == fixed["fixed-debian.bag"]
    assert '"std_msgs/ColorRGBA", "a29a96539573343b1310c73607334b00"' in fixed["fixed-ours.bag"]
    assert "[1.0, 0.0, 0.5, 1.0]" in fixed["fixed-ours.bag"]  # inside Marker.colors too
    # without the rules, fix refuses and leaves no bag
    ours, theirs = both(tmp_path, "bag", "fix", "-n", "old.bag", "none.bag")
    assert (ours.returncode, ours.stdout) == (theirs.returncode, theirs.stdout) == (1, theirs.stdout)
    assert not (tmp_path / "none.bag.tmp").exists()


ROSBAG_MAIN = r'''
import contextlib, io, json, os, shutil, sys
from rosbag import Bag, Compression
from rosbag import rosbag_main as rm
folder, source = sys.argv[1], sys.argv[2]
out = {}
text = io.StringIO()
with contextlib.redirect_stdout(text):
    cmds = rm.RosbagCmds()
    cmds.add_cmd("info", rm.info_cmd, "Summarize the contents of one or more bag files.")
    cmds.help_cmd([])
out["help"] = text.getvalue()
out["valid"] = cmds.get_valid_cmds()
bag = os.path.join(folder, "a.bag")
shutil.copy(source, bag)
compress = lambda inbag, outbag, quiet: rm.change_compression_op(inbag, outbag, Compression.BZ2, quiet)
rm.bag_op([bag], False, True, lambda b: False, compress, None, False, True)
with Bag(bag) as b:
    out["compressed"] = [b.get_compression_info().compression, b.get_message_count()]
out["backup"] = os.path.exists(os.path.join(folder, "a.orig.bag"))
os.makedirs(os.path.join(folder, "o"))
rm.bag_op([bag], True, True, lambda b: b.version > 102,
          lambda i, o, quiet: rm.reindex_op(i, o, quiet), os.path.join(folder, "o"), False, True)
with Bag(os.path.join(folder, "o", "a.bag")) as b:
    out["reindexed"] = [b.get_message_count(), b.get_compression_info().compression]
from rosbag import migration as mg
out["names"] = [[mg.clean_name(n, top), mg.qualified_name(n, top)] for n, top in (
    ("std_msgs/Header", "pkg/T"), ("pkg/Sub", "pkg/T"), ("Sub", "pkg/T"), ("Header", "a/B"),
    ("other/X", "pkg/T"), ("float64", "pkg/T"))]
out["defaults"] = [mg.migration_default_value(t) for t in (
    "int8", "float32", "string", "uint8[]", "uint8[4]", "int32[]", "float64[3]", "bool",
    "geometry_msgs/Point", "Header")]
out["constants"] = sorted(map(list, mg.constants_from_def(
    "p/T", "int32 A=1\nstring S=hi\nfloat64 x\n" + "=" * 80 + "\nMSG: p/U\nint8 B=2\n")))
out["keys"] = [mg.get_message_key(Bag), mg.get_path_key(Bag, Bag)]
print(json.dumps(out, sort_keys=True))
'''


def test_rosbag_main_api_like_debian(bagdir, tmp_path):
    """rosbag.rosbag_main's pieces (the command table and its help, bag_op with
    change_compression_op and reindex_op) do to a bag what Debian's do."""
    results = []
    for python, env in ((PYTHON, dict(os.environ)), (REFERENCE_PYTHON, reference_env({}))):
        folder = tmp_path / Path(python).name
        folder.mkdir()
        run = subprocess.run([python, "-c", ROSBAG_MAIN, str(folder), str(bagdir / "deb.bag")],
                             env=env, capture_output=True, text=True, timeout=60)
        assert run.returncode == 0, run.stderr
        results.append(run.stdout)
    assert results[0] == results[1]
    assert '"compressed": ["bz2", 254]' in results[0]
