#!/usr/bin/env python3
"""point_cloud2 benchmark: minros's numpy read_points/create_cloud beside Debian's module.

    .venv/bin/python benchmarks/point_cloud2.py [--points 200000] [--rounds 3]

One cloud of ``--points`` points (x, y, z, intensity float32 and rgb uint32, 20 bytes each) is
read with ``list(read_points(cloud))`` and with ``skip_nans=True``, and made again with
``create_cloud`` from the list of tuples and (minros only) from an (N, 5) numpy array. minros
runs in this process, Debian's sensor_msgs.point_cloud2 under /usr/bin/python3 on the same
bytes; contenders alternate round by round and the median time per round is shown.
"""

from __future__ import annotations

import argparse
import json
import os
import statistics
import subprocess
import sys
import tempfile
import time

REFERENCE = r'''
import json, sys, time
from sensor_msgs import point_cloud2
from sensor_msgs.msg import PointCloud2, PointField
from std_msgs.msg import Header
data = open(sys.argv[1], "rb").read()
n = int(sys.argv[2])
fields = [PointField(c, 4 * i, PointField.FLOAT32, 1) for i, c in enumerate("xyzi")]
fields.append(PointField("rgb", 16, PointField.UINT32, 1))
cloud = PointCloud2(height=1, width=n, fields=fields, point_step=20, row_step=20 * n, data=data)
out = {}
t = time.perf_counter(); points = list(point_cloud2.read_points(cloud)); out["read"] = time.perf_counter() - t
t = time.perf_counter(); list(point_cloud2.read_points(cloud, skip_nans=True)); out["read_skip_nans"] = time.perf_counter() - t
t = time.perf_counter(); point_cloud2.create_cloud(Header(), fields, points); out["create_list"] = time.perf_counter() - t
print(json.dumps(out))
'''


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--points", type=int, default=200000)
    parser.add_argument("--rounds", type=int, default=3)
    args = parser.parse_args()
    import numpy as np

    from minros import point_cloud2
    from minros.msgs import get_message_class

    PointCloud2 = get_message_class("sensor_msgs/PointCloud2")
    PointField = get_message_class("sensor_msgs/PointField")
    Header = get_message_class("std_msgs/Header")
    n = args.points
    rng = np.random.default_rng(1)
    xyzi = rng.normal(size=(n, 4)).astype(np.float32)
    xyzi[rng.random(n) < 0.1, 0] = np.nan
    records = np.zeros(n, dtype=[("xyzi", "<f4", 4), ("rgb", "<u4")])
    records["xyzi"] = xyzi
    records["rgb"] = rng.integers(0, 1 << 24, n)
    data = records.tobytes()
    fields = [PointField(c, 4 * i, PointField.FLOAT32, 1) for i, c in enumerate("xyzi")]
    fields.append(PointField("rgb", 16, PointField.UINT32, 1))
    cloud = PointCloud2(height=1, width=n, fields=fields, point_step=20, row_step=20 * n, data=data)
    array = np.column_stack([xyzi, records["rgb"]]).astype(np.float32)[:, :4]
    fields4 = fields[:4]
    results = {"minros": {}, "Debian": {}}
    with tempfile.NamedTemporaryFile(suffix=".bin", delete=False) as f:
        f.write(data)
    try:
        for _ in range(args.rounds):
            ours = {}
            t = time.perf_counter()
            points = list(point_cloud2.read_points(cloud))
            ours["read"] = time.perf_counter() - t
            t = time.perf_counter()
            list(point_cloud2.read_points(cloud, skip_nans=True))
            ours["read_skip_nans"] = time.perf_counter() - t
            t = time.perf_counter()
            point_cloud2.create_cloud(Header(), fields, points)
            ours["create_list"] = time.perf_counter() - t
            t = time.perf_counter()
            point_cloud2.create_cloud(Header(), fields4, array)
            ours["create_numpy (x,y,z,i)"] = time.perf_counter() - t
            for key, value in ours.items():
                results["minros"].setdefault(key, []).append(value)
            env = {k: v for k, v in os.environ.items() if k not in ("PYTHONPATH", "VIRTUAL_ENV")}
            run = subprocess.run(["/usr/bin/python3", "-c", REFERENCE, f.name, str(n)],
                                 capture_output=True, text=True, env=env, timeout=600)
            if run.returncode != 0:
                print(run.stderr, file=sys.stderr)
                return 1
            for key, value in json.loads(run.stdout).items():
                results["Debian"].setdefault(key, []).append(value)
    finally:
        os.unlink(f.name)
    keys = list(results["minros"])
    print(f"{n} points, median of {args.rounds} rounds (seconds)")
    print(f"{'operation':<26}{'minros':>10}{'Debian':>10}{'speed-up':>10}")
    for key in keys:
        ours = statistics.median(results["minros"][key])
        theirs = results["Debian"].get(key)
        if theirs:
            ref = statistics.median(theirs)
            print(f"{key:<26}{ours:>10.3f}{ref:>10.3f}{ref / ours:>9.1f}x")
        else:
            print(f"{key:<26}{ours:>10.3f}{'-':>10}{'':>10}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
