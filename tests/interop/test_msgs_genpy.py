"""minros messages against Debian's genpy: md5 sums, full texts, bytes, str() and rosmsg output."""

from __future__ import annotations

import json
import subprocess
import sys

import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from minros.msgs import generate_dynamic, get_message_class, get_service_class
from minros.msgs.testing import GenpyOracle, bundled_services, bundled_types, strategy_for, to_plain
from support import REFERENCE_PYTHON, debian_has_messages, reference_env, require_reference

pytestmark = pytest.mark.interop

# the packages whose classes Debian's Python has (test_msg_packages.py checks the others
# against the classes Debian's genpy generates from the same files)
DEBIAN_TYPES = [t for t in bundled_types() if debian_has_messages(t.split("/")[0])]
DEBIAN_SERVICES = [t for t in bundled_services() if debian_has_messages(t.split("/")[0])]

DUMP = r'''
import importlib, json, sys
out = {}
for item in json.loads(sys.stdin.read()):
    kind, type_name = item
    pkg, name = type_name.split("/")
    part = name.endswith(("Request", "Response")) and kind == "msg"
    mod = importlib.import_module(pkg + (".msg" if kind == "msg" and not part else ".srv"))
    if part and not hasattr(mod, name):
        mod = importlib.import_module(pkg + ".msg")
    cls = getattr(mod, name)
    out[kind + ":" + type_name] = [cls._md5sum, getattr(cls, "_full_text", None)]
print(json.dumps(out))
'''


@pytest.fixture(scope="module")
def debian_definitions() -> dict:
    require_reference()
    request = [["msg", t] for t in DEBIAN_TYPES] + [["srv", t] for t in DEBIAN_SERVICES]
    out = subprocess.run([REFERENCE_PYTHON, "-c", DUMP], input=json.dumps(request),
                         capture_output=True, text=True, env=reference_env({}), timeout=120)
    assert out.returncode == 0, out.stderr
    return json.loads(out.stdout)


def test_every_md5_and_full_text_equals_debian(debian_definitions: dict) -> None:
    assert len(debian_definitions) == len(DEBIAN_TYPES) + len(DEBIAN_SERVICES)
    mismatches = []
    for type_name in DEBIAN_TYPES:
        md5, full_text = debian_definitions["msg:" + type_name]
        cls = get_message_class(type_name)
        if cls._md5sum != md5:
            mismatches.append(f"md5 {type_name}")
        if cls._full_text != full_text:
            mismatches.append(f"full text {type_name}")
    for type_name in DEBIAN_SERVICES:
        md5, _ = debian_definitions["srv:" + type_name]
        if get_service_class(type_name)._md5sum != md5:
            mismatches.append(f"srv md5 {type_name}")
    assert mismatches == []


@pytest.fixture(scope="module")
def oracle():
    require_reference()
    proc = GenpyOracle(env=reference_env({}))
    yield proc
    proc.close()


@pytest.mark.parametrize("type_name", DEBIAN_TYPES)
@settings(max_examples=5, deadline=None, database=None, suppress_health_check=list(HealthCheck))
@given(data=st.data())
def test_bytes_equal_genpy(oracle: GenpyOracle, type_name: str, data) -> None:
    msg = data.draw(strategy_for(type_name))
    ours = msg.serialize_to_bytes()
    assert ours == oracle.serialize(type_name, msg)
    # and genpy reads our bytes back to the same values
    assert oracle.deserialize(type_name, ours) == to_plain(get_message_class(type_name)().deserialize(ours))


STR_CASES = {
    "std_msgs/String": {"data": "hello: world"},
    "geometry_msgs/PoseStamped": {"header": {"seq": 3, "stamp": [5, 7], "frame_id": "map"},
                                  "pose": {"position": {"x": 1.5, "y": 0.0, "z": -2.0},
                                           "orientation": {"x": 0.0, "y": 0.0, "z": 0.0, "w": 1.0}}},
    "rosgraph_msgs/Log": {"header": {"seq": 0, "stamp": [0, 0], "frame_id": ""}, "level": 2,
                          "name": "/n", "msg": "it's", "file": "", "function": "f", "line": 3,
                          "topics": ["/a", "/b"]},
    "std_msgs/UInt8MultiArray": {"layout": {"dim": [{"label": "x", "size": 2, "stride": 2}],
                                            "data_offset": 0}, "data": {"b": "0102"}},
}

STR_SCRIPT = r'''
import json, sys
sys.path.insert(0, "")
exec(sys.stdin.readline())
cases = json.loads(sys.stdin.readline())
out = {}
for type_name, plain in cases.items():
    out[type_name] = str(build(find_class(type_name), plain))
print(json.dumps(out))
'''


def test_str_equals_genpy() -> None:
    require_reference()
    from minros.msgs.testing import GENPY_ORACLE

    helpers = GENPY_ORACLE.split("for line in sys.stdin:")[0]
    script = helpers + "\ncases = json.loads(sys.stdin.read())\nprint(json.dumps({t: str(build(find_class(t), p)) for t, p in cases.items()}))\n"
    out = subprocess.run([REFERENCE_PYTHON, "-c", script], input=json.dumps(STR_CASES),
                         capture_output=True, text=True, env=reference_env({}), timeout=60)
    assert out.returncode == 0, out.stderr
    theirs = json.loads(out.stdout)
    for type_name, plain in STR_CASES.items():
        msg = _build(type_name, plain)
        assert str(msg) == theirs[type_name], type_name


def _build(type_name: str, plain):
    from minros.msgs import Duration, Time

    cls = get_message_class(type_name)
    msg = cls()
    for name, slot_type in zip(cls.__slots__, cls._slot_types):
        setattr(msg, name, _value(slot_type, plain[name], Time, Duration))
    return msg


def _value(slot_type: str, plain, Time, Duration):
    base = slot_type.split("[")[0]
    if "[" in slot_type:
        if base in ("uint8", "char"):
            return bytes.fromhex(plain["b"])
        return [_value(base, v, Time, Duration) for v in plain]
    if base == "time":
        return Time(*plain)
    if base == "duration":
        return Duration(*plain)
    if isinstance(plain, dict):
        return _build(base, plain)
    return plain


def test_generate_dynamic_from_genpy_full_text(debian_definitions: dict) -> None:
    _md5, full_text = debian_definitions["msg:visualization_msgs/MarkerArray"]
    classes = generate_dynamic("visualization_msgs/MarkerArray", full_text)
    assert classes["visualization_msgs/MarkerArray"]._md5sum == _md5
    assert "std_msgs/Header" in classes and "geometry_msgs/Point" in classes


@pytest.mark.parametrize("tool, args", [
    ("rosmsg", ["show", "std_msgs/Header"]),
    ("rosmsg", ["show", "-r", "std_msgs/Header"]),
    ("rosmsg", ["show", "geometry_msgs/PoseStamped"]),
    ("rosmsg", ["show", "rosgraph_msgs/Log"]),
    ("rosmsg", ["show", "sensor_msgs/PointCloud2"]),
    ("rosmsg", ["info", "Header"]),
    ("rosmsg", ["md5", "sensor_msgs/Image"]),
    ("rosmsg", ["package", "std_msgs"]),
    ("rosmsg", ["package", "-s", "geometry_msgs"]),
    ("rossrv", ["show", "std_srvs/SetBool"]),
    ("rossrv", ["show", "-r", "roscpp/SetLoggerLevel"]),
    ("rossrv", ["show", "Empty"]),
    ("rossrv", ["md5", "std_srvs/Trigger"]),
    ("rossrv", ["package", "roscpp"]),
])
def test_cli_output_equals_debian(tool: str, args: list) -> None:
    require_reference()
    theirs = subprocess.run([f"/usr/bin/{tool}", *args], capture_output=True, text=True,
                            env=reference_env({}), timeout=60)
    ours = subprocess.run([sys.executable, "-m", "minros", tool[3:], *args], capture_output=True,
                          text=True, timeout=60)
    assert theirs.returncode == 0, theirs.stderr
    assert ours.returncode == 0, ours.stderr
    assert ours.stdout == theirs.stdout


@pytest.mark.parametrize("tool, args", [
    ("msg", ["show", "std_msgs/Nope"]),
    ("msg", ["show", "nopkg/Nope"]),
    ("msg", ["md5", "std_msgs/Nope"]),
    ("msg", ["show", "NoSuchTypeAnywhere"]),
    ("srv", ["show", "std_srvs/Nope"]),
])
def test_cli_unknown_type_one_line(tool: str, args: list) -> None:
    out = subprocess.run([sys.executable, "-m", "minros", tool, *args], capture_output=True,
                         text=True, timeout=60)
    assert out.returncode != 0
    assert out.stdout == ""
    assert len(out.stderr.strip().splitlines()) == 1 and "Traceback" not in out.stderr
