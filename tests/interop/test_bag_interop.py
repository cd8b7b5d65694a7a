"""rosbag: minros's recorder, player and Bag API against Debian's rosbag (C++ record/play,
Python Bag and CLI), plus MCAP read back with the ``mcap`` library.

Bags minros records (plain, lz4, bz2, split) are read by Debian's ``rosbag info``, ``rosbag
play`` and ``rosbag.Bag``; bags Debian's ``rosbag record`` wrote are read and played by minros;
a recorder killed with SIGKILL is recovered by ``rosbag reindex``; bad input gets one line.
"""

from __future__ import annotations

import json
import os
import re
import resource
import signal
import subprocess
import time
from pathlib import Path
from typing import Dict, List

import pytest

from integration.pubsub_scripts import TALKER
from support import (
    PYTHON,
    REFERENCE_PYTHON,
    Proc,
    reference_env,
    require_reference,
    ros_env,
    wait_until,
)

pytestmark = pytest.mark.interop


def _env(port: int, home: Path) -> Dict[str, str]:
    return ros_env(port, home)


def minros_bag(port: int, home: Path, cwd: Path, *argv: str, timeout: float = 60,
               **kw) -> subprocess.CompletedProcess:
    return subprocess.run([PYTHON, "-m", "minros", "bag", *argv], env=_env(port, home), cwd=cwd,
                          capture_output=True, text=True, timeout=timeout, **kw)


def debian_rosbag(port: int, home: Path, cwd: Path, *argv: str,
                  timeout: float = 60) -> subprocess.CompletedProcess:
    return subprocess.run(["/usr/bin/rosbag", *argv], env=reference_env(_env(port, home)), cwd=cwd,
                          capture_output=True, text=True, timeout=timeout)


def debian_read(path: Path) -> List[list]:
    """[topic, type, data-or-len, secs, nsecs] of every message, read by Debian's rosbag.Bag."""
    code = (
        "import json, sys, rosbag\n"
        "out = []\n"
        "with rosbag.Bag(sys.argv[1]) as b:\n"
        "    for topic, m, t in b.read_messages():\n"
        "        v = m.data if isinstance(m.data, str) else len(m.data)\n"
        "        out.append([topic, m._type, v, t.secs, t.nsecs])\n"
        "print(json.dumps(out))\n")
    result = subprocess.run([REFERENCE_PYTHON, "-c", code, str(path)], env=reference_env({}),
                            capture_output=True, text=True, timeout=60)
    assert result.returncode == 0, result.stderr
    return json.loads(result.stdout)


@pytest.fixture
def talker(tmp_path: Path, debian_rosmaster, ros_home):
    """A minros node publishing String 'msg N' on /chatter at 20 Hz once someone listens."""
    require_reference()
    script = tmp_path / "talker.py"
    script.write_text(TALKER)
    proc = Proc([PYTHON, str(script), "/chatter", "string", "100000", "20", "0", "__name:=talker"],
                _env(debian_rosmaster, ros_home))
    yield proc
    proc.stop()


def _no_traceback(text: str) -> None:
    assert "Traceback" not in text, text


@pytest.mark.parametrize("flag,compression", [(None, "none"), ("--lz4", "lz4"), ("-j", "bz2")])
def test_minros_record_read_by_debian(talker, debian_rosmaster, ros_home, tmp_path, flag, compression):
    args = ["record", "-l", "15", "-O", "rec"] + ([flag] if flag else []) + ["/chatter"]
    result = minros_bag(debian_rosmaster, ros_home, tmp_path, *args)
    assert result.returncode == 0, result.stdout + result.stderr
    assert "Recording to 'rec.bag'." in result.stdout + result.stderr
    info = debian_rosbag(debian_rosmaster, ros_home, tmp_path, "info", "rec.bag")
    assert info.returncode == 0, info.stderr
    assert re.search(r"^messages:\s+15$", info.stdout, re.M), info.stdout
    assert re.search(r"^compression:\s+" + compression, info.stdout, re.M), info.stdout
    assert re.search(r"/chatter\s+15 msgs\s+: std_msgs/String", info.stdout), info.stdout
    messages = debian_read(tmp_path / "rec.bag")
    numbers = [int(m[2].split()[1]) for m in messages]
    assert len(messages) == 15 and all(m[:2] == ["/chatter", "std_msgs/String"] for m in messages)
    assert numbers == list(range(numbers[0], numbers[0] + 15))  # in order, none lost
    stamps = [m[3] + m[4] / 1e9 for m in messages]
    assert stamps == sorted(stamps) and 0.5 < stamps[-1] - stamps[0] < 1.5  # 14 periods of 50 ms
    # the same bag, played by Debian's player, reaches a Debian subscriber
    echo = Proc(["/usr/bin/rostopic", "echo", "-n", "3", "/chatter"],
                reference_env(_env(debian_rosmaster, ros_home)))
    try:
        time.sleep(1.0)  # rostopic echo registers before the player advertises
        play = debian_rosbag(debian_rosmaster, ros_home, tmp_path, "play", "-q", "-d", "1", "rec.bag")
        assert play.returncode == 0, play.stderr
        out = echo.output(timeout=15)
    finally:
        echo.stop()
    assert out.count('data: "msg ') == 3, out


def test_minros_split_read_by_debian(talker, debian_rosmaster, ros_home, tmp_path):
    rec = Proc([PYTHON, "-m", "minros", "bag", "record", "--split", "--duration", "1", "-O", "part",
                "/chatter"], _env(debian_rosmaster, ros_home), cwd=tmp_path)
    try:
        wait_until(lambda: len(list(tmp_path.glob("part_*.bag"))) >= 3, 20, what="3 closed splits")
    finally:
        out = rec.stop()
    _no_traceback(out)
    parts = sorted(tmp_path.glob("part_*.bag"), key=lambda p: int(p.stem.split("_")[1]))
    assert [p.name for p in parts[:3]] == ["part_0.bag", "part_1.bag", "part_2.bag"]
    total = []
    for part in parts:
        info = debian_rosbag(debian_rosmaster, ros_home, tmp_path, "info", "-y", "-k", "duration", part.name)
        assert info.returncode == 0, info.stderr
        assert float(info.stdout) < 1.2, (part, info.stdout)
        total += debian_read(part)
    numbers = [int(m[2].split()[1]) for m in total]
    assert numbers == list(range(numbers[0], numbers[0] + len(numbers)))  # no gap between files


@pytest.mark.parametrize("recorder", ["debian", "minros"])
def test_record_duration_ends_as_debians(talker, debian_rosmaster, ros_home, tmp_path, recorder):
    """rosbag record --duration 2, Debian's and minros's on the same talker: each stops by
    itself with 0, after at most 2 s of messages; nothing published, each leaves an empty bag."""
    run = debian_rosbag if recorder == "debian" else minros_bag
    began = time.monotonic()
    rec = run(debian_rosmaster, ros_home, tmp_path, "record", "--duration", "2", "-O", "short",
              "/chatter", timeout=30)
    took = time.monotonic() - began
    assert rec.returncode == 0, rec.stdout + rec.stderr
    _no_traceback(rec.stderr)
    messages = debian_read(tmp_path / "short.bag")
    stamps = [m[3] + m[4] / 1e9 for m in messages]
    assert took >= 2.0 and 20 <= len(messages) <= 41, (took, len(messages))
    assert stamps[-1] - stamps[0] <= 2.0
    idle = run(debian_rosmaster, ros_home, tmp_path, "record", "--duration", "1", "-O", "idle",
               "/nothing", timeout=30)
    assert idle.returncode == 0, idle.stdout + idle.stderr
    assert debian_read(tmp_path / "idle.bag") == []


def test_debian_record_read_and_played_by_minros(talker, debian_rosmaster, ros_home, tmp_path):
    rec = debian_rosbag(debian_rosmaster, ros_home, tmp_path, "record", "-l", "12", "-O", "deb",
                        "/chatter")
    assert rec.returncode == 0, rec.stderr
    code = ("import sys, json\nfrom minros.bag import Bag\n"
            "with Bag(sys.argv[1]) as b:\n"
            "    out = [[t, m.data, s.to_nsec(), type(m).__module__] for t, m, s in b.read_messages()]\n"
            "    info = b.get_type_and_topic_info()\n"
            "print(json.dumps([out, info.msg_types, b.get_message_count()]))\n")
    result = subprocess.run([PYTHON, "-c", code, str(tmp_path / "deb.bag")], capture_output=True,
                            text=True, timeout=60)
    assert result.returncode == 0, result.stderr
    out, types, count = json.loads(result.stdout)
    assert count == 12 and types == {"std_msgs/String": "992ce8a1687cec8c8bd883ec73ca41d1"}
    assert [m[0] for m in out] == ["/chatter"] * 12 and all(m[1].startswith("msg ") for m in out)
    debian_times = [m[3] * 10**9 + m[4] for m in debian_read(tmp_path / "deb.bag")]
    assert [m[2] for m in out] == debian_times
    ours = minros_bag(debian_rosmaster, ros_home, tmp_path, "info", "deb.bag")
    theirs = debian_rosbag(debian_rosmaster, ros_home, tmp_path, "info", "deb.bag")
    assert ours.stdout.replace("@ 20.0 Hz", "") == theirs.stdout.replace("@ 20.0 Hz", "")
    # minros plays it to a Debian subscriber on another topic name (-p prefix)
    echo = Proc(["/usr/bin/rostopic", "echo", "-n", "2", "/replay/chatter"],
                reference_env(_env(debian_rosmaster, ros_home)))
    try:
        time.sleep(1.0)
        play = minros_bag(debian_rosmaster, ros_home, tmp_path, "play", "-p", "/replay", "-d", "1", "deb.bag")
        assert play.returncode == 0, play.stderr
        assert "Done." in play.stdout
        out_echo = echo.output(timeout=15)
    finally:
        echo.stop()
    assert out_echo.count('data: "msg ') == 2, out_echo


def test_minros_mcap_read_by_mcap_library(talker, debian_rosmaster, ros_home, tmp_path):
    result = minros_bag(debian_rosmaster, ros_home, tmp_path, "record", "-l", "10", "-O", "rec.mcap", "/chatter")
    assert result.returncode == 0, result.stderr
    from mcap.reader import make_reader

    with open(tmp_path / "rec.mcap", "rb") as f:
        reader = make_reader(f)
        assert reader.get_header().profile == "ros1"
        summary = reader.get_summary()
        (schema,) = summary.schemas.values()
        (channel,) = summary.channels.values()
        messages = list(reader.iter_messages())
    assert (schema.name, schema.encoding, schema.data) == ("std_msgs/String", "ros1msg", b"string data\n")
    assert channel.topic == "/chatter" and channel.message_encoding == "ros1"
    assert channel.metadata["md5sum"] == "992ce8a1687cec8c8bd883ec73ca41d1"
    assert len(messages) == 10
    data = messages[0][2].data  # ros1 encoding: uint32 length + the string
    assert int.from_bytes(data[:4], "little") == len(data) - 4 and data[4:].startswith(b"msg ")
    info = minros_bag(debian_rosmaster, ros_home, tmp_path, "info", "rec.mcap")
    assert re.search(r"/chatter\s+10 msgs\s+: std_msgs/String", info.stdout), info.stdout


def test_sigkill_recorder_reindex_recovers(talker, debian_rosmaster, ros_home, tmp_path):
    rec = Proc([PYTHON, "-m", "minros", "bag", "record", "-O", "crash", "/chatter"],
               _env(debian_rosmaster, ros_home), cwd=tmp_path)
    try:
        rec.read_until("Recording to 'crash.bag'.", 20)
        time.sleep(4.0)  # 4 s of a 20 Hz topic
        os.killpg(rec.pid, signal.SIGKILL)
        rec.popen.wait(10)
    finally:
        rec.stop()
    active = tmp_path / "crash.bag.active"
    assert active.exists() and not (tmp_path / "crash.bag").exists()
    info = debian_rosbag(debian_rosmaster, ros_home, tmp_path, "info", active.name)
    assert info.returncode == 1 and "Run rosbag reindex" in info.stderr
    reindex = minros_bag(debian_rosmaster, ros_home, tmp_path, "reindex", active.name)
    assert reindex.returncode == 0, reindex.stderr
    assert (tmp_path / "crash.bag.orig.active").exists()  # rosbag keeps the original
    messages = debian_read(active)
    stamps = [m[3] + m[4] / 1e9 for m in messages]
    assert len(messages) >= 60 and stamps[-1] - stamps[0] >= 2.9, (len(messages), stamps[-1] - stamps[0])


def _write_bag(path: Path, code: str) -> None:
    result = subprocess.run([PYTHON, "-c", "from minros.bag import Bag\nimport minros\n" + code, str(path)],
                            capture_output=True, text=True, timeout=60)
    assert result.returncode == 0, result.stderr


def test_bad_input_one_line_each(debian_rosmaster, ros_home, tmp_path):
    require_reference()
    _write_bag(tmp_path / "good.bag", (
        "import sys\nfrom std_msgs.msg import String\n"
        "with Bag(sys.argv[1], 'w', chunk_threshold=2000) as b:\n"
        "    for i in range(300):\n"
        "        b.write('/s', String('m%03d' % i + 'x' * 60), minros.Time(100 + i, 0))\n"))
    data = (tmp_path / "good.bag").read_bytes()
    cases = {}
    (tmp_path / "truncated.bag").write_bytes(data[: len(data) * 2 // 3])
    cases["truncated.bag"] = "ERROR bag unindexed: truncated.bag.  Run rosbag reindex."
    # a chunk written after the index, as a recorder appending without closing leaves it
    unindexed = bytearray(data)
    at = data.index(b"index_pos=") + len("index_pos=")
    unindexed[at:at + 8] = b"\0" * 8
    (tmp_path / "unindexed.bag").write_bytes(bytes(unindexed))
    (tmp_path / "notabag.bag").write_text("hello, I am a text file\n")
    cases["notabag.bag"] = "ERROR reading notabag.bag: This does not appear to be a bag file"
    for name, expected in cases.items():
        result = minros_bag(debian_rosmaster, ros_home, tmp_path, "info", name)
        assert result.returncode == 1 and result.stderr.strip() == expected, (name, result.stderr)
        _no_traceback(result.stdout + result.stderr)
        theirs = debian_rosbag(debian_rosmaster, ros_home, tmp_path, "info", name)
        assert theirs.returncode == 1 and theirs.stderr.strip() == expected, (name, theirs.stderr)
    result = minros_bag(debian_rosmaster, ros_home, tmp_path, "info", "unindexed.bag")
    assert result.returncode == 1 and "Run rosbag reindex" in result.stderr
    for name in ("truncated.bag", "unindexed.bag"):
        fixed = minros_bag(debian_rosmaster, ros_home, tmp_path, "reindex", "-q", name)
        assert fixed.returncode == 0, fixed.stderr
        messages = debian_read(tmp_path / name)
        assert len(messages) >= (300 if name == "unindexed.bag" else 150)
        assert [m[2][:4] for m in messages] == [f"m{i:03d}" for i in range(len(messages))]
    play = minros_bag(debian_rosmaster, ros_home, tmp_path, "play", "notabag.bag")
    assert play.returncode == 1 and "notabag.bag" in play.stderr and "not appear to be a bag" in play.stderr
    _no_traceback(play.stdout + play.stderr)


SECRET_DEF = "string word\nint32 number\n"


def test_play_types_nobody_installed(debian_rosmaster, ros_home, tmp_path):
    """A bag of my_pkg/Secret (installed nowhere) plays; the subscriber decodes it from the
    definition the player sends, and Debian's rosbag.Bag reads it too."""
    require_reference()
    _write_bag(tmp_path / "secret.bag", (
        "import sys\nfrom minros.msgs import generate_dynamic\n"
        f"cls = generate_dynamic('my_pkg/Secret', {SECRET_DEF!r})['my_pkg/Secret']\n"
        "with Bag(sys.argv[1], 'w') as b:\n"
        "    for i in range(5):\n"
        "        b.write('/secret', cls(word='w%d' % i, number=i), minros.Time(200 + i, 0))\n"))
    code = ("import sys, rosbag\n"
            "print([(m.word, m.number) for _t, m, _s in rosbag.Bag(sys.argv[1]).read_messages()])\n")
    theirs = subprocess.run([REFERENCE_PYTHON, "-c", code, str(tmp_path / "secret.bag")],
                            env=reference_env({}), capture_output=True, text=True, timeout=60)
    assert theirs.stdout.strip() == str([(f"w{i}", i) for i in range(5)]), theirs.stderr
    echo = Proc([PYTHON, "-m", "minros", "topic", "echo", "-n", "2", "/secret"],
                _env(debian_rosmaster, ros_home))
    try:
        echo.read_until("does not appear to be published yet", 15)
        play = minros_bag(debian_rosmaster, ros_home, tmp_path, "play", "-d", "1", "secret.bag")
        assert play.returncode == 0, play.stderr
        out = echo.output(timeout=15)
    finally:
        echo.stop()
    assert 'word: "w0"\nnumber: 0\n---\nword: "w1"\nnumber: 1\n---' in out, out


def test_full_disk_keeps_what_was_written(debian_rosmaster, ros_home, tmp_path):
    """A file-size limit (RLIMIT_FSIZE) stands in for a full disk: one error line, exit 1, and
    the messages written before are in a readable bag."""
    require_reference()
    script = tmp_path / "talker.py"
    script.write_text(TALKER)
    talker = Proc([PYTHON, str(script), "/big", "image", "100000", "30", "0"],
                  _env(debian_rosmaster, ros_home))
    limit = 40 * 1024 * 1024

    def cap() -> None:
        resource.setrlimit(resource.RLIMIT_FSIZE, (limit, limit))

    try:
        result = subprocess.run([PYTHON, "-m", "minros", "bag", "record", "-O", "full", "/big"],
                                env=_env(debian_rosmaster, ros_home), cwd=tmp_path, preexec_fn=cap,
                                capture_output=True, text=True, timeout=90)
    finally:
        talker.stop()
    output = result.stdout + result.stderr
    _no_traceback(output)
    assert result.returncode == 1, output
    errors = [line for line in output.splitlines() if "Error writing to full.bag.active" in line]
    assert len(errors) == 1 and "File too large" in errors[0] and "full.bag" in errors[0], output
    info = debian_rosbag(debian_rosmaster, ros_home, tmp_path, "info", "-y", "-k", "messages", "full.bag")
    assert info.returncode == 0 and int(info.stdout) >= 3, info.stdout + info.stderr


def _chunk_frames(path: Path) -> List[tuple]:
    """(compression, uncompressed size, data) of each CHUNK record of a bag v2.0 file, read
    with nothing but struct: a second opinion on the layout, independent of minros."""
    import struct

    raw = path.read_bytes()
    assert raw.startswith(b"#ROSBAG V2.0\n")
    pos, out = 13, []
    while pos < len(raw):
        (hlen,) = struct.unpack_from("<I", raw, pos)
        fields, at = {}, pos + 4
        while at < pos + 4 + hlen:
            (flen,) = struct.unpack_from("<I", raw, at)
            name, _, value = raw[at + 4:at + 4 + flen].partition(b"=")
            fields[name] = value
            at += 4 + flen
        (dlen,) = struct.unpack_from("<I", raw, at)
        if fields[b"op"] == b"\x05":
            out.append((fields[b"compression"].decode(), struct.unpack("<I", fields[b"size"])[0],
                        raw[at + 4:at + 4 + dlen]))
        pos = at + 4 + dlen
    return out


def _debian_roslz4(frames: List[bytes], tmp_path: Path) -> List[int]:
    """Sizes Debian's roslz4.decompress gives for each frame."""
    paths = []
    for i, frame in enumerate(frames):
        (tmp_path / f"frame{i}.lz4").write_bytes(frame)
        paths.append(str(tmp_path / f"frame{i}.lz4"))
    code = ("import sys, roslz4\n"
            "print([len(roslz4.decompress(open(p, 'rb').read())) for p in sys.argv[1:]])\n")
    result = subprocess.run([REFERENCE_PYTHON, "-c", code, *paths], env=reference_env({}),
                            capture_output=True, text=True, timeout=60)
    assert result.returncode == 0, result.stderr
    return json.loads(result.stdout)


def test_lz4_image_bag_multi_block_chunks_read_by_debian(debian_rosmaster, ros_home, tmp_path):
    """`rosbag record --lz4` of 1080p images: each chunk is an LZ4 frame of several 1 MB blocks,
    which Debian's rosbag (info, check, rosbag.Bag) and roslz4 itself decompress."""
    require_reference()
    script = tmp_path / "talker.py"
    script.write_text(TALKER)
    talker = Proc([PYTHON, str(script), "/cam", "image", "100000", "5", "0"],
                  _env(debian_rosmaster, ros_home))
    try:
        result = minros_bag(debian_rosmaster, ros_home, tmp_path, "record", "--lz4", "-l", "3",
                            "-O", "img", "/cam")
    finally:
        talker.stop()
    assert result.returncode == 0, result.stdout + result.stderr
    frames = _chunk_frames(tmp_path / "img.bag")
    assert frames and all(c == "lz4" for c, _n, _d in frames)
    assert max(n for _c, n, _d in frames) > 3 << 20  # more than three of roslz4's 1 MB blocks
    assert _debian_roslz4([d for _c, _n, d in frames], tmp_path) == [n for _c, n, _d in frames]
    info = debian_rosbag(debian_rosmaster, ros_home, tmp_path, "info", "img.bag")
    assert info.returncode == 0, info.stderr
    assert re.search(r"^compression:\s+lz4", info.stdout, re.M), info.stdout
    assert re.search(r"/cam\s+3 msgs\s+: sensor_msgs/Image", info.stdout), info.stdout
    check = debian_rosbag(debian_rosmaster, ros_home, tmp_path, "check", "img.bag")
    assert check.returncode == 0 and "does not need any migrations" in check.stdout, check.stderr
    code = ("import sys, json, rosbag\n"
            "out = []\n"
            "for _t, m, _s in rosbag.Bag(sys.argv[1]).read_messages():\n"
            "    out.append([m.width, m.height, len(m.data), len(set(m.data))])\n"
            "print(json.dumps(out))\n")
    read = subprocess.run([REFERENCE_PYTHON, "-c", code, str(tmp_path / "img.bag")],
                          env=reference_env({}), capture_output=True, text=True, timeout=60)
    assert read.returncode == 0, read.stderr
    assert json.loads(read.stdout) == [[1920, 1080, 1920 * 1080 * 3, 1]] * 3


def debian_read_images(path: Path) -> List[list]:
    code = ("import sys, json, rosbag\n"
            "print(json.dumps([[len(m.data), t.secs] for _t, m, t in rosbag.Bag(sys.argv[1]).read_messages()]))\n")
    result = subprocess.run([REFERENCE_PYTHON, "-c", code, str(path)], env=reference_env({}),
                            capture_output=True, text=True, timeout=60)
    assert result.returncode == 0, result.stderr
    return json.loads(result.stdout)


@pytest.mark.smoke
def test_lz4_bag_api_multi_block_chunks_read_by_debian(tmp_path):
    """The Bag API's lz4 compression, chunks of 4 MB of varied bytes, read back by Debian."""
    require_reference()
    _write_bag(tmp_path / "api.bag", (
        "import sys, random\nfrom sensor_msgs.msg import Image\n"
        "rng = random.Random(7)\n"
        "with Bag(sys.argv[1], 'w', compression='lz4', chunk_threshold=4 << 20) as b:\n"
        "    for i in range(6):\n"
        "        data = bytes(rng.getrandbits(8) for _ in range(4096)) * 400\n"
        "        b.write('/img', Image(width=len(data), height=1, encoding='mono8', step=len(data),\n"
        "                              data=data), minros.Time(10 + i, 0))\n"))
    frames = _chunk_frames(tmp_path / "api.bag")
    assert len(frames) >= 2 and all(n > 2 << 20 for _c, n, _d in frames)
    assert _debian_roslz4([d for _c, _n, d in frames], tmp_path) == [n for _c, n, _d in frames]
    messages = debian_read_images(tmp_path / "api.bag")
    assert messages == [[4096 * 400, 10 + i] for i in range(6)]



def test_debian_appends_to_and_reindexes_minros_bags(tmp_path):
    """Debian's rosbag rewrites the file header of a bag it appends to or reindexes, in its
    own size (4104 bytes): minros's bags have that layout, so their first chunk survives."""
    require_reference()
    for name in ("a.bag", "cut.bag"):
        _write_bag(tmp_path / name, (
            "import sys\nfrom std_msgs.msg import String\n"
            "with Bag(sys.argv[1], 'w', chunk_threshold=1000) as b:\n"
            "    for i in range(200):\n"
            "        b.write('/s', String('m%03d' % i + 'x' * 40), minros.Time(100 + i, 0))\n"))
    code = ("import sys, rospy, rosbag\nfrom std_msgs.msg import String\n"
            "with rosbag.Bag(sys.argv[1], 'a') as b:\n"
            "    b.write('/s', String('m200'), rospy.Time(300, 0))\n")
    appended = subprocess.run([REFERENCE_PYTHON, "-c", code, str(tmp_path / "a.bag")],
                              env=reference_env({}), capture_output=True, text=True, timeout=60)
    assert appended.returncode == 0, appended.stderr
    assert [m[2][:4] for m in debian_read(tmp_path / "a.bag")] == [f"m{i:03d}" for i in range(201)]
    data = (tmp_path / "cut.bag").read_bytes()
    (tmp_path / "cut.bag").write_bytes(data[:len(data) // 2])
    reindex = debian_rosbag(0, tmp_path, tmp_path, "reindex", "-q", "cut.bag")
    assert reindex.returncode == 0, reindex.stderr
    messages = debian_read(tmp_path / "cut.bag")
    assert len(messages) >= 60 and [m[2][:4] for m in messages] == [f"m{i:03d}" for i in range(len(messages))]
    for name in ("a.bag", "cut.bag"):  # and minros reads both
        code = ("import sys\nfrom minros.bag import Bag\n"
                "print(len(list(Bag(sys.argv[1]).read_messages())))\n")
        ours = subprocess.run([PYTHON, "-c", code, str(tmp_path / name)], capture_output=True,
                              text=True, timeout=60)
        assert ours.returncode == 0 and int(ours.stdout) == (201 if name == "a.bag" else len(messages)), ours.stderr
