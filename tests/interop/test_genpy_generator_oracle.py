"""genpy.generator (minros.msgs.pygen) writes the modules Debian's genpy writes, byte for byte,
for every message and service package both have."""

from __future__ import annotations

import filecmp
import subprocess
from pathlib import Path

import pytest

from support import PYTHON, REFERENCE_PYTHON, reference_env, require_reference

pytestmark = pytest.mark.interop

PACKAGES = ["std_msgs", "geometry_msgs", "sensor_msgs", "nav_msgs", "visualization_msgs",
            "diagnostic_msgs", "actionlib_msgs", "tf2_msgs", "trajectory_msgs", "shape_msgs",
            "stereo_msgs", "std_srvs", "rosgraph_msgs"]

# Generates every package from Debian's definitions (/usr/share/<pkg>), in one process as
# catkin's per-package run would: the temporaries' numbering carries over between files.
GENERATE = r"""
import glob, os, sys
from genpy.generator import MsgGenerator, SrvGenerator
out = sys.argv[1]
search = {}
for share in glob.glob('/usr/share/*/msg'):
    search.setdefault(os.path.basename(os.path.dirname(share)), []).append(share)
for pkg in sys.argv[2:]:
    for kind, gen in (('msg', MsgGenerator()), ('srv', SrvGenerator())):
        files = sorted(glob.glob('/usr/share/%s/%s/*.%s' % (pkg, kind, kind)))
        if files and gen.generate_messages(pkg, files, os.path.join(out, pkg, kind), search):
            sys.exit('generation failed: ' + pkg)
"""


def differing(left: Path, right: Path) -> list:
    cmp = filecmp.dircmp(left, right)
    out = [str(left / n) for n in cmp.diff_files + cmp.left_only + cmp.right_only]
    for sub in cmp.common_dirs:
        out += differing(left / sub, right / sub)
    return out


def test_generated_modules_equal_debian_genpy(tmp_path: Path):
    require_reference()
    if not Path("/usr/share/std_msgs/msg").is_dir():
        pytest.skip("Debian's message definitions are not installed")
    packages = [p for p in PACKAGES if Path(f"/usr/share/{p}").is_dir()]
    debian, minros = tmp_path / "debian", tmp_path / "minros"
    subprocess.run([REFERENCE_PYTHON, "-c", GENERATE, str(debian), *packages], check=True,
                   env=reference_env({}), timeout=300)
    # the venv's interpreter: its genpy is minros's (it does not see Debian's dist-packages)
    subprocess.run([PYTHON, "-c", GENERATE, str(minros), *packages], check=True, timeout=300)
    files = list(debian.rglob("_*.py"))
    assert len(files) > 100
    assert differing(debian, minros) == []
