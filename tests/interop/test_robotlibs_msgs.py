"""The message packages Debian lacks (smach_msgs, tf2_web_republisher): md5 sums and full texts
equal to what ROS's own generators compute from the same files: Debian's genaction.py expands
the .action and genmsg computes every sum (genpy takes its _md5sum from genmsg)."""

from __future__ import annotations

import json
import subprocess
from pathlib import Path

import pytest

from minros.msgs import get_message_class, get_service_class
from support import REFERENCE_PYTHON, need, reference_env, reference_imports

pytestmark = pytest.mark.interop

SHARE = Path(__import__("minros.msgs", fromlist=["x"]).__file__).parent / "share"

ORACLE = r'''
import glob, json, os, subprocess, sys, tempfile
import genmsg, genmsg.msg_loader as ml
from genmsg.gentools import compute_md5, compute_full_text
share, pkgs = sys.argv[1], sys.argv[2:]
search = {}
for p in os.listdir("/usr/share"):
    if os.path.isdir(os.path.join("/usr/share", p, "msg")):
        search[p] = [os.path.join("/usr/share", p, "msg")]
out = {}
tmp = tempfile.mkdtemp()
for pkg in pkgs:
    dirs = [os.path.join(share, pkg, "msg")]
    for action in glob.glob(os.path.join(share, pkg, "action", "*.action")):
        gen = os.path.join(tmp, pkg)
        subprocess.run([sys.executable, "/usr/lib/actionlib_msgs/genaction.py", "-o", gen, action],
                       check=True, capture_output=True)
        dirs.append(gen)
    search[pkg] = [d for d in dirs if os.path.isdir(d)]
for pkg in pkgs:
    for d in search[pkg]:
        for f in sorted(glob.glob(os.path.join(d, "*.msg"))):
            ctx = genmsg.MsgContext.create_default()
            name = pkg + "/" + os.path.basename(f)[:-4]
            spec = ml.load_msg_from_file(ctx, f, name)
            ml.load_depends(ctx, spec, search)
            out["msg:" + name] = [compute_md5(ctx, spec), compute_full_text(ctx, spec)]
    for f in sorted(glob.glob(os.path.join(share, pkg, "srv", "*.srv"))):
        ctx = genmsg.MsgContext.create_default()
        name = pkg + "/" + os.path.basename(f)[:-4]
        spec = ml.load_srv_from_file(ctx, f, name)
        ml.load_depends(ctx, spec, search)
        out["srv:" + name] = [compute_md5(ctx, spec), None]
print(json.dumps(out))
'''


def test_upstream_packages_have_ros_md5_sums_and_full_texts() -> None:
    need(reference_imports("genmsg") and Path("/usr/lib/actionlib_msgs/genaction.py").exists(),
         "Debian's genmsg and actionlib_msgs' genaction.py are not installed",
         "scripts/install-ros-reference.sh")
    done = subprocess.run([REFERENCE_PYTHON, "-c", ORACLE, str(SHARE), "smach_msgs",
                           "tf2_web_republisher"], capture_output=True, text=True,
                          env=reference_env({}), timeout=120)
    assert done.returncode == 0, done.stderr
    oracle = json.loads(done.stdout)
    # the three smach messages, TFArray, the seven TFSubscription action types, RepublishTFs
    assert len(oracle) == 3 + 1 + 7 + 1, sorted(oracle)
    for key, (md5, full_text) in oracle.items():
        kind, name = key.split(":")
        if kind == "msg":
            cls = get_message_class(name)
            assert cls._md5sum == md5, name
            assert cls._full_text == full_text, name
        else:
            assert get_service_class(name)._md5sum == md5, name
