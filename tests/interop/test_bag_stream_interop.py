"""``rosbag.Bag`` on file objects: one script, through Debian's rosbag and through minros's
stand-in, gives the same answers (filename, what close() does to the file object, messages
read and appended, an unindexed file's handling), and each reads the other's file."""

from __future__ import annotations

import json
import subprocess
from pathlib import Path

import pytest

from support import PYTHON, REFERENCE_PYTHON, reference_env, require_reference

pytestmark = pytest.mark.interop

SCRIPT = r'''
import json, os, sys
import rosbag, rospy
from std_msgs.msg import String

d = sys.argv[1]
out = {}
p = os.path.join(d, "w.bag")
f = open(p, "wb")
b = rosbag.Bag(f, "w")
b.write("/s", String("a"), rospy.Time(10))
out["filename"] = b.filename
out["mode"] = b.mode
b.close()
out["closed after writing"] = f.closed

f = open(p, "rb")
b = rosbag.Bag(f)
out["read"] = [m.message.data for m in b.read_messages()]
out["size is the file's"] = b.size == os.path.getsize(p)
out["info rows"] = [line.split(":")[0] for line in str(b).splitlines()[:2]]
out["yaml rows"] = [line.split(":")[0] for line in b._get_yaml_info().splitlines()[:2]]
b.close()
out["closed after reading"] = f.closed

f = open(p, "r+b")
b = rosbag.Bag(f, "a")
b.write("/s", String("b"), rospy.Time(11))
b.close()
out["closed after appending"] = f.closed
out["appended"] = [m.message.data for m in rosbag.Bag(p).read_messages()]

u = os.path.join(d, "u.bag")
b = rosbag.Bag(u, "w")
b.write("/s", String("c"), rospy.Time(12))
b.flush()
f = open(u, "rb")
try:
    rosbag.Bag(f)
except rosbag.ROSBagUnindexedException as exc:
    out["unindexed"] = [str(exc), f.closed]
b.close()
print(json.dumps(out))
'''


def _run(python: str, directory: Path) -> dict:
    directory.mkdir()
    env = reference_env({}) if python == REFERENCE_PYTHON else None
    result = subprocess.run([python, "-c", SCRIPT, str(directory)], env=env, capture_output=True,
                            text=True, timeout=60)
    assert result.returncode == 0, result.stderr
    return json.loads(result.stdout)


READ = "import sys, rosbag\nprint([m.message.data for m in rosbag.Bag(open(sys.argv[1], 'rb')).read_messages()])\n"


def test_file_objects_as_debian(tmp_path):
    require_reference()
    theirs = _run(REFERENCE_PYTHON, tmp_path / "debian")
    ours = _run(PYTHON, tmp_path / "minros")
    assert theirs["filename"] is None and theirs["closed after writing"] is True  # the facts
    assert theirs["appended"] == ["a", "b"] and theirs["unindexed"] == ["Unindexed bag", True]
    assert ours == theirs
    for python, other in ((REFERENCE_PYTHON, "minros"), (PYTHON, "debian")):
        env = reference_env({}) if python == REFERENCE_PYTHON else None
        read = subprocess.run([python, "-c", READ, str(tmp_path / other / "w.bag")], env=env,
                              capture_output=True, text=True, timeout=60)
        assert read.stdout.strip() == "['a', 'b']", read.stderr
