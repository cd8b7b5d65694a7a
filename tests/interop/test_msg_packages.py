"""Every bundled message package against ROS's own generators: md5 sums and full texts of every
message (the types catkin generates from ``.action`` files included) and every service equal to
Debian's generated classes where Debian's Python has the package, and otherwise to what Debian's
genmsg computes from the same files after Debian's genaction.py has expanded the actions, as a
catkin build would; bytes equal to the classes Debian's genpy generates from them."""

from __future__ import annotations

import json
import os
import subprocess
from pathlib import Path

import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from minros.msgs import get_message_class, get_service_class
from minros.msgs.registry import type_names_in
from minros.msgs.testing import GenpyOracle, strategy_for, to_plain
from minros.packages import BUILTIN_SHARE_DIRS
from support import REFERENCE_PYTHON, debian_has_messages, reference_env, require_reference

pytestmark = pytest.mark.interop

SHARE = BUILTIN_SHARE_DIRS[0]
PACKAGES = sorted(p.name for p in SHARE.iterdir()
                  if any((p / kind).is_dir() for kind in ("msg", "srv", "action")))
MESSAGES = [f"{pkg}/{name}" for pkg in PACKAGES for name in type_names_in(SHARE / pkg, "msg")]
SERVICES = [f"{pkg}/{name}" for pkg in PACKAGES for name in type_names_in(SHARE / pkg, "srv")]
#: the packages checked against classes Debian's genpy generates here (Debian lacks them)
GENERATED = [pkg for pkg in PACKAGES if not debian_has_messages(pkg)]

# Run by Debian's interpreter. Expands each package's actions with Debian's genaction.py, then
# for every type answers genmsg's md5 and full text (messages) or md5 (services), and writes the
# genpy classes of the packages Debian lacks into `outdir` for the byte-level tests. The search
# path is Debian's own definitions for the packages Debian installs them for, and the bundled
# ones otherwise (pcl_msgs, which jsk_recognition_msgs uses, is itself checked against Debian).
REFERENCE = r'''
import json, os, subprocess, sys
import genmsg, genmsg.msg_loader
from genpy.generator import MsgGenerator, SrvGenerator
from genpy.generate_initpy import write_modules

req = json.loads(sys.stdin.read())
share, out = req["share"], req["outdir"]
search = {}
for pkg in os.listdir("/usr/share"):
    if os.path.isdir(os.path.join("/usr/share", pkg, "msg")):
        search[pkg] = [os.path.join("/usr/share", pkg, "msg")]
for pkg in req["packages"]:
    if pkg in search and pkg not in req["generate"]:
        continue
    folder = os.path.join(share, pkg)
    search[pkg] = [os.path.join(folder, "msg")]
    if os.path.isdir(os.path.join(folder, "action")):
        target = os.path.join(out, "_actions", pkg)
        for name in sorted(os.listdir(os.path.join(folder, "action"))):
            subprocess.run([sys.executable, "/usr/lib/actionlib_msgs/genaction.py",
                            os.path.join(folder, "action", name), "-o", target],
                           check=True, stdout=subprocess.DEVNULL)
        search[pkg].append(target)
answer = {"md5": {}, "failures": 0}
context = genmsg.MsgContext.create_default()
for type_name in req["messages"]:
    spec = genmsg.msg_loader.load_msg_by_type(context, type_name, search)
    genmsg.msg_loader.load_depends(context, spec, search)
    answer["md5"]["msg:" + type_name] = [genmsg.compute_md5(context, spec),
                                         genmsg.compute_full_text(context, spec)]
for type_name in req["services"]:
    pkg, name = type_name.split("/")
    path = os.path.join(share, pkg, "srv", name + ".srv")
    spec = genmsg.msg_loader.load_srv_from_file(context, path, type_name)
    genmsg.msg_loader.load_depends(context, spec, search)
    answer["md5"]["srv:" + type_name] = [genmsg.compute_md5(context, spec), None]
for pkg in req["generate"]:
    msgs = [os.path.join(d, f) for d in search[pkg] if os.path.isdir(d)
            for f in sorted(os.listdir(d)) if f.endswith(".msg")]
    srv_dir = os.path.join(share, pkg, "srv")
    srvs = ([os.path.join(srv_dir, f) for f in sorted(os.listdir(srv_dir)) if f.endswith(".srv")]
            if os.path.isdir(srv_dir) else [])
    os.makedirs(os.path.join(out, pkg), exist_ok=True)
    open(os.path.join(out, pkg, "__init__.py"), "w").close()
    for gen, files, kind in ((MsgGenerator(), msgs, "msg"), (SrvGenerator(), srvs, "srv")):
        if files:
            answer["failures"] += gen.generate_messages(pkg, files, os.path.join(out, pkg, kind), search)
            write_modules(os.path.join(out, pkg, kind))
print(json.dumps(answer))
'''

# Run by Debian's interpreter: md5 and full text of Debian's own generated classes.
DEBIAN_CLASSES = r'''
import importlib, json, sys
out = {}
for kind, type_name in json.loads(sys.stdin.read()):
    pkg, name = type_name.split("/")
    cls = getattr(importlib.import_module(pkg + "." + kind), name)
    out[kind + ":" + type_name] = [cls._md5sum, getattr(cls, "_full_text", None)]
print(json.dumps(out))
'''


@pytest.fixture(scope="module")
def reference(tmp_path_factory) -> dict:
    """{"md5": {"msg:pkg/T": [md5, full text]}, "classes": folder of generated classes}."""
    require_reference()
    outdir = tmp_path_factory.mktemp("genpy")
    request = {"share": str(SHARE), "outdir": str(outdir), "packages": PACKAGES,
               "generate": GENERATED, "messages": MESSAGES, "services": SERVICES}
    run = subprocess.run([REFERENCE_PYTHON, "-c", REFERENCE], input=json.dumps(request),
                         capture_output=True, text=True, env=reference_env({}), timeout=300)
    assert run.returncode == 0, run.stderr[-3000:]
    answer = json.loads(run.stdout)
    assert answer["failures"] == 0
    in_debian = [[kind, t] for kind, names in (("msg", MESSAGES), ("srv", SERVICES))
                 for t in names if debian_has_messages(t.split("/")[0])]
    run = subprocess.run([REFERENCE_PYTHON, "-c", DEBIAN_CLASSES], input=json.dumps(in_debian),
                         capture_output=True, text=True, env=reference_env({}), timeout=120)
    assert run.returncode == 0, run.stderr[-3000:]
    return {"genmsg": answer["md5"], "debian": json.loads(run.stdout), "classes": outdir}


def _mismatches(ours: dict, theirs: dict) -> list:
    return [key for key in ours if ours[key] != theirs[key]]


def _ours(kind: str, type_name: str) -> list:
    if kind == "srv":
        return [get_service_class(type_name)._md5sum, None]
    cls = get_message_class(type_name)
    return [cls._md5sum, cls._full_text]


def test_packages_debian_has_equal_its_classes(reference: dict) -> None:
    theirs = reference["debian"]
    ours = {key: _ours(*key.split(":")) for key in theirs}
    # the desktop-full packages Debian ships only as generated classes are among them
    assert {"map_msgs/GetMapROI", "move_base_msgs/MoveBaseActionGoal", "pcl_msgs/PolygonMesh",
            "polled_camera/GetPolledImage", "rviz/SendFilePath"} <= {k.split(":")[1] for k in ours}
    assert len(ours) > 200
    assert _mismatches(ours, theirs) == []


def test_packages_debian_lacks_equal_genmsg_on_the_same_files(reference: dict) -> None:
    theirs = {k: v for k, v in reference["genmsg"].items()
              if not debian_has_messages(k.split(":")[1].split("/")[0])}
    ours = {key: _ours(*key.split(":")) for key in theirs}
    assert {"control_msgs", "gazebo_msgs", "moveit_msgs", "ackermann_msgs", "mavros_msgs"} <= set(GENERATED)
    assert len(ours) > 600
    assert _mismatches(ours, theirs) == []


def test_genmsg_agrees_with_debian_where_both_answer(reference: dict) -> None:
    """The search path the genmsg check uses is sound: on the packages Debian has, genmsg run
    over the bundled files gives Debian's md5 sums."""
    theirs = reference["debian"]
    assert [k for k in theirs if reference["genmsg"][k][0] != theirs[k][0]] == []


@pytest.fixture(scope="module")
def oracle(reference: dict):
    env = reference_env({})
    env["PYTHONPATH"] = str(reference["classes"])
    proc = GenpyOracle(env=env)
    yield proc
    proc.close()


#: every message type of the packages Debian lacks, bytes checked against genpy's classes
GENERATED_TYPES = [t for t in MESSAGES if t.split("/")[0] in GENERATED]


@pytest.mark.parametrize("type_name", GENERATED_TYPES)
@settings(max_examples=2, deadline=None, database=None, suppress_health_check=list(HealthCheck))
@given(data=st.data())
def test_bytes_equal_genpy_generated(oracle: GenpyOracle, type_name: str, data) -> None:
    msg = data.draw(strategy_for(type_name))
    ours = msg.serialize_to_bytes()
    assert ours == oracle.serialize(type_name, msg)
    assert oracle.deserialize(type_name, ours) == to_plain(get_message_class(type_name)().deserialize(ours))


def test_every_package_has_licence_manifest_and_stand_in() -> None:
    stubs = Path(__file__).resolve().parents[2] / "stubs"
    problems = []
    for pkg in PACKAGES:
        folder = SHARE / pkg
        if not list(folder.glob("COPYRIGHT*")):
            problems.append(f"{pkg}: no COPYRIGHT")
        if f"<name>{pkg}</name>" not in (folder / "package.xml").read_text():
            problems.append(f"{pkg}: package.xml names another package")
        for kind in ("msg", "srv"):
            if type_names_in(folder, kind) and not (stubs / pkg / kind / "__init__.py").is_file():
                problems.append(f"{pkg}: no stubs/{pkg}/{kind}")
    assert problems == []
    assert os.path.isdir(stubs / "control_msgs" / "msg")
