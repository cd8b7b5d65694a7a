"""sensor_msgs.point_cloud2 (numpy in minros) against Debian's module on random clouds."""

from __future__ import annotations

import json
import subprocess

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from minros import point_cloud2
from minros.msgs import get_message_class
from support import REFERENCE_PYTHON, reference_env, require_reference

pytestmark = pytest.mark.interop

PointCloud2 = get_message_class("sensor_msgs/PointCloud2")
PointField = get_message_class("sensor_msgs/PointField")
SIZES = {1: 1, 2: 1, 3: 2, 4: 2, 5: 4, 6: 4, 7: 4, 8: 8}

ORACLE = r'''
import json, sys
from sensor_msgs import point_cloud2
from sensor_msgs.msg import PointCloud2, PointField
from std_msgs.msg import Header

def plain(values):
    return [[repr(v) for v in p] for p in values]

for line in sys.stdin:
    req = json.loads(line)
    fields = [PointField(n, o, d, c) for n, o, d, c in req["fields"]]
    try:
        if req["op"] == "read":
            cloud = PointCloud2(height=req["height"], width=req["width"], fields=fields,
                                is_bigendian=req["big"], point_step=req["point_step"],
                                row_step=req["row_step"], data=bytes.fromhex(req["data"]))
            out = {"points": plain(point_cloud2.read_points(cloud, req["names"], req["skip_nans"],
                                                            req["uvs"]))}
        else:
            points = [tuple(p) for p in req["points"]]
            cloud = point_cloud2.create_cloud(Header(frame_id="f"), fields, points)
            out = {"data": cloud.data.hex(), "point_step": cloud.point_step, "width": cloud.width}
    except Exception as exc:
        out = {"exc": type(exc).__name__}
    print(json.dumps(out), flush=True)
'''


@pytest.fixture(scope="module")
def oracle():
    require_reference()
    proc = subprocess.Popen([REFERENCE_PYTHON, "-c", ORACLE], stdin=subprocess.PIPE,
                            stdout=subprocess.PIPE, text=True, env=reference_env({}))

    def ask(req: dict) -> dict:
        proc.stdin.write(json.dumps(req) + "\n")
        proc.stdin.flush()
        return json.loads(proc.stdout.readline())

    yield ask
    proc.stdin.close()
    proc.wait(10)


@st.composite
def clouds(draw):
    fields, offset = [], 0
    for i in range(draw(st.integers(1, 4))):
        offset += draw(st.integers(0, 3))
        datatype = draw(st.integers(1, 8))
        count = draw(st.integers(1, 2))
        fields.append([f"c{i}", offset, datatype, count])
        offset += SIZES[datatype] * count
    point_step = offset + draw(st.integers(0, 4))
    width, height = draw(st.integers(0, 5)), draw(st.integers(0, 3))
    row_step = width * point_step + draw(st.integers(0, 5))
    data = draw(st.binary(min_size=row_step * height, max_size=row_step * height))
    names = draw(st.one_of(st.none(), st.lists(st.sampled_from([f[0] for f in fields] + ["nope"]),
                                               max_size=3)))
    uvs = draw(st.lists(st.tuples(st.integers(0, max(width - 1, 0)),
                                  st.integers(0, max(height - 1, 0))), max_size=3)) \
        if width and height and draw(st.booleans()) else []
    return {"op": "read", "fields": fields, "big": draw(st.booleans()), "width": width,
            "height": height, "point_step": point_step, "row_step": row_step, "data": data.hex(),
            "names": names, "skip_nans": draw(st.booleans()), "uvs": uvs}


def _ours(req: dict) -> dict:
    fields = [PointField(n, o, d, c) for n, o, d, c in req["fields"]]
    try:
        if req["op"] == "read":
            cloud = PointCloud2(height=req["height"], width=req["width"], fields=fields,
                                is_bigendian=req["big"], point_step=req["point_step"],
                                row_step=req["row_step"], data=bytes.fromhex(req["data"]))
            values = point_cloud2.read_points(cloud, req["names"], req["skip_nans"], req["uvs"])
            return {"points": [[repr(v) for v in p] for p in values]}
        points = req["points"] if not req.get("numpy") else np.array(req["points"])
        cloud = point_cloud2.create_cloud(get_message_class("std_msgs/Header")(frame_id="f"),
                                          fields, points)
        return {"data": bytes(cloud.data).hex(), "point_step": cloud.point_step, "width": cloud.width}
    except Exception as exc:  # the type is compared
        return {"exc": type(exc).__name__}


@settings(max_examples=300, deadline=None, database=None, suppress_health_check=list(HealthCheck))
@given(req=clouds())
def test_read_points_equals_ros(oracle, req: dict) -> None:
    assert _ours(req) == oracle(req)


@settings(max_examples=150, deadline=None, database=None, suppress_health_check=list(HealthCheck))
@given(data=st.data())
def test_create_cloud_equals_ros(oracle, data) -> None:
    fields, offset = [], 0
    for i in range(data.draw(st.integers(1, 3))):
        offset += data.draw(st.integers(0, 2))
        datatype = data.draw(st.sampled_from([2, 5, 7, 8]))
        fields.append([f"c{i}", offset, datatype, 1])
        offset += SIZES[datatype]
    ints = {2: st.integers(0, 255), 5: st.integers(-(1 << 31), (1 << 31) - 1)}
    floats = st.floats(-1e6, 1e6, width=32)
    row = st.tuples(*[ints.get(f[2], floats) for f in fields]).map(list)
    points = data.draw(st.lists(row, max_size=6))
    as_numpy = data.draw(st.booleans()) and all(f[2] in (7, 8) for f in fields) and points
    req = {"op": "create", "fields": fields, "points": points, "numpy": bool(as_numpy)}
    assert _ours(req) == oracle(dict(req, numpy=False))


def test_read_points_list_names_the_fields() -> None:
    header = get_message_class("std_msgs/Header")()
    cloud = point_cloud2.create_cloud_xyz32(header, np.array([[1.0, 2.0, 3.0], [4.0, 5.0, np.nan]]))
    assert cloud.width == 2 and cloud.point_step == 12
    points = point_cloud2.read_points_list(cloud, skip_nans=True)
    assert [(p.x, p.y, p.z) for p in points] == [(1.0, 2.0, 3.0)]
