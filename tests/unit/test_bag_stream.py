"""``rosbag.Bag`` on file objects, as ROS's: ``Bag(open('x.bag', 'wb'), 'w')``, reading an open
binary file, appending through one opened ``r+b``; ``filename`` is None, ``close()`` closes
the file object, a text-mode file is refused in rosbag's words. An ``io.BytesIO`` (which ROS's
Bag does not take) works too, and stays open. tests/interop/test_bag_stream_interop.py runs
the same calls through Debian's rosbag and compares."""

from __future__ import annotations

import io

import pytest

import minros
from minros.bag import Bag, ROSBagException, ROSBagUnindexedException
from std_msgs.msg import Int32, String


def _write(f, mode: str = "w", first: int = 0, n: int = 3, **kw) -> Bag:
    b = Bag(f, mode, **kw)
    for i in range(first, first + n):
        b.write("/s", String(f"m{i}"), minros.Time(10 + i))
        b.write("/i", Int32(i), minros.Time(10 + i, 1))
    return b


def _strings(path) -> list:
    with Bag(str(path)) as b:
        return [m.message.data for m in b.read_messages("/s")]


def test_write_to_an_open_file(tmp_path):
    path = tmp_path / "w.bag"
    f = open(path, "wb")  # noqa: SIM115 - the bag closes it
    b = _write(f)
    assert b.filename is None and b.mode == "w" and b.size > 4117
    b.close()
    assert f.closed  # as rosbag: close() closes the file object it was given
    b.close()  # closing twice does nothing
    assert _strings(path) == ["m0", "m1", "m2"]


def test_read_from_an_open_file(tmp_path):
    path = tmp_path / "r.bag"
    _write(str(path)).close()
    f = open(path, "rb")  # noqa: SIM115
    with Bag(f) as b:
        assert b.filename is None and b.size == path.stat().st_size
        assert [m.message.data for m in b.read_messages("/i")] == [0, 1, 2]
        assert b.get_message_count() == 6
        text = str(b)
        assert text.startswith("version:") and "path:" not in text and "messages:    6" in text
        assert not b._get_yaml_info().startswith("path:")
    assert f.closed


def test_append_through_an_open_file(tmp_path):
    path = tmp_path / "a.bag"
    _write(str(path)).close()
    with open(path, "r+b") as f:
        _write(f, "a", first=3).close()
        assert f.closed
    assert _strings(path) == [f"m{i}" for i in range(6)]


def test_text_mode_file_is_refused(tmp_path):
    path = tmp_path / "t.bag"
    _write(str(path)).close()
    with open(path, encoding="latin-1") as f, \
            pytest.raises(ROSBagException, match="^In Python 3 the bag file must be opened in binary mode$"):
        Bag(f)


def test_unindexed_file_object_is_closed_as_rosbag_does(tmp_path):
    path = tmp_path / "u.bag"
    b = _write(str(path))
    b.flush()  # the chunks are written, the index is not
    f = open(path, "rb")  # noqa: SIM115
    with pytest.raises(ROSBagUnindexedException):
        Bag(f)
    assert f.closed
    b.close()
    with open(path, "rb") as f, Bag(f, allow_unindexed=True) as b2:
        assert b2.get_message_count() == 6


def test_bytesio_round_trip_stays_open():
    buf = io.BytesIO()
    with _write(buf, compression="lz4"):
        pass
    assert not buf.closed  # the bag just written would be lost with it
    with _write(buf, "a", first=3):
        pass
    with Bag(buf) as b:
        assert [m.message.data for m in b.read_messages("/s")] == [f"m{i}" for i in range(6)]
        assert [c.compression for c in b._chunk_summaries()] == ["lz4", "none"]
    with Bag(io.BytesIO(buf.getvalue())) as b:
        assert b.get_message_count() == 12
    with Bag(io.BytesIO(), "a") as b:  # appending to nothing starts a bag
        b.write("/i", Int32(7), minros.Time(1))
    with pytest.raises(ROSBagException, match="empty file"):
        Bag(io.BytesIO())
