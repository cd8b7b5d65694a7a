"""tf_conversions, tf2_kdl, tf2_sensor_msgs, laser_geometry and image_geometry against
Debian's packages: geometry_libs_script.py runs on random inputs under both interpreters and
the answers must agree (numbers within 1e-9; clouds byte for byte; the image_geometry
undistortion maps byte for byte).

Two known differences are asserted as such: Debian's tf2_kdl cannot attach the tf2 header to
its pybind11 PyKDL objects (AttributeError in do_transform_* and tf2_ros.Stamped; minros's work),
and an image remapped by OpenCV 4.6 (Debian) and by PyPI's OpenCV differs by a few grey levels
(the maps fed to it are identical).
"""

from __future__ import annotations

import json
import os
import subprocess
from pathlib import Path

import numpy as np
import pytest

from minros.kdl.testing import differences
from support import PYTHON, REFERENCE_PYTHON, need, reference_env, reference_imports, run_python

pytestmark = pytest.mark.interop

SCRIPT = Path(__file__).with_name("geometry_libs_script.py")
MODULES = "PyKDL, tf_conversions, tf2_kdl, tf2_sensor_msgs, laser_geometry, image_geometry"


def run_both(seed: int):
    need(reference_imports(MODULES), "Debian's python3-pykdl, -tf-conversions, -tf2-kdl, "
         "-tf2-sensor-msgs, -laser-geometry and -image-geometry are not all installed",
         "scripts/install-ros-reference.sh")
    theirs = subprocess.run([REFERENCE_PYTHON, str(SCRIPT), str(seed)], capture_output=True,
                            text=True, env=reference_env({}), timeout=120)
    assert theirs.returncode == 0, theirs.stderr[-2000:]
    env = dict(os.environ)
    env.pop("PYTHONPATH", None)
    ours = subprocess.run([PYTHON, str(SCRIPT), str(seed)], capture_output=True, text=True,
                          env=env, timeout=120)
    assert ours.returncode == 0, ours.stderr[-2000:]
    return json.loads(ours.stdout), json.loads(theirs.stdout)


@pytest.mark.parametrize("seed", [1, 2])
def test_geometry_libraries_match_debian(seed):
    ours, theirs = run_both(seed)
    for key in ("posemath", "posemath_names", "tf2_sensor_msgs", "laser_geometry",
                "laser_constants", "stereo"):
        found = differences(ours[key], theirs[key], 1e-9)
        assert not found, (key, found[:5])

    for mine, debian in zip(ours["tf2_kdl"], theirs["tf2_kdl"]):
        assert (debian["do_transform_vector"], debian["stamped"]) == ("AttributeError",) * 2
        assert (mine["do_transform_vector"], mine["stamped"]) == (None, None)
        for name in ("transform_to_kdl", "vector", "frame", "twist", "wrench"):
            assert not differences(mine[name], debian[name], 1e-9), name

    for mine, debian in zip(ours["pinhole"], theirs["pinhole"]):
        image_a, image_b = np.array(mine.pop("rectified")), np.array(debian.pop("rectified"))
        found = differences(mine, debian, 1e-9)
        assert not found, found[:5]
        assert image_a.shape == image_b.shape
        gap = np.abs(image_a - image_b)
        # random noise is the worst case for cubic interpolation; OpenCV versions differ a little
        assert gap.mean() < 2.0 and gap.max() <= 16, (gap.mean(), gap.max())

    # the comparison covered real data: clouds with points, scans with returns, every channel
    assert sum(len(c["data"]) for c in ours["tf2_sensor_msgs"]) > 2000
    assert sum(c["shape"][1] for c in ours["laser_geometry"]) > 300
    assert {f[0] for c in ours["laser_geometry"] for f in c["fields"]} >= {
        "x", "y", "z", "intensity", "index", "distances", "stamps", "vp_x"}


def test_stand_ins_import_without_debian():
    """minros's stand-ins import in a clean environment (no Debian packages on the path)."""
    code = ("import PyKDL, tf_conversions, tf2_kdl, tf2_sensor_msgs, laser_geometry, "
            "image_geometry; print(PyKDL.__file__)")
    result = run_python(code, {})
    assert result.returncode == 0, result.stderr
    assert "/usr/lib/python3/dist-packages" not in result.stdout
