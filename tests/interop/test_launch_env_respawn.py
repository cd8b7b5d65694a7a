"""roslaunch's process rules next to Debian's roslaunch, on the same launch file:

- a ``respawn="true"`` node that exits with status 0 is started again (ROS's process monitor
  respawns whatever the exit status; only rostest has no rosout to fight over, see
  tests/integration/test_rostest_nodes.py), one without respawn is left dead;
- ``<env>`` reaches the nodes after it in its scope: launch level, group, include, node, in
  file order, as roslaunch's loader copies a scope's environment when a child scope opens.
"""

from __future__ import annotations

import os
import time
from pathlib import Path

import pytest

from support import PYTHON, Proc, free_port, need, reference_env, ros_env, wait_until

pytestmark = pytest.mark.interop

ROSLAUNCH = str(Path(PYTHON).parent / "roslaunch")

DUMP = """#!/usr/bin/env python
import os, sys
name = [a for a in sys.argv if a.startswith("__name:=")][0][len("__name:="):]
keys = ("A_TOP", "B_GROUP", "C_INC", "D_AFTER", "ROS_NAMESPACE")
with open(os.path.join(os.environ["OUT_DIR"], name), "a") as out:
    out.write(" ".join("%s=%s" % (k, os.environ.get(k)) for k in keys) + "\\n")
"""

ENVS = """<launch>
  <node name="first" pkg="launch_parity" type="dump_env.py"/>
  <env name="A_TOP" value="top"/>
  <node name="n1" pkg="launch_parity" type="dump_env.py"/>
  <group ns="g">
    <env name="B_GROUP" value="grp"/>
    <node name="n2" pkg="launch_parity" type="dump_env.py"/>
  </group>
  <node name="n3" pkg="launch_parity" type="dump_env.py"/>
  <include file="$(find launch_parity)/inc.launch">
    <env name="C_INC" value="inc"/>
  </include>
  <env name="D_AFTER" value="after"/>
  <node name="n5" pkg="launch_parity" type="dump_env.py"><env name="A_TOP" value="mine"/></node>
  <node name="respawned" pkg="launch_parity" type="dump_env.py" respawn="true"/>
  <node name="waiter" pkg="rostopic" type="rostopic" args="echo /nothing"/>
</launch>
"""


def _package(root: Path) -> Path:
    pkg = root / "launch_parity"
    pkg.mkdir(parents=True)
    (pkg / "package.xml").write_text("<package format='2'><name>launch_parity</name>"
                                     "<version>0.0.1</version></package>\n")
    script = pkg / "dump_env.py"
    script.write_text(DUMP)
    script.chmod(0o755)
    (pkg / "envs.launch").write_text(ENVS)
    (pkg / "inc.launch").write_text(
        '<launch><node name="n4" pkg="launch_parity" type="dump_env.py"/></launch>\n')
    return pkg


def _launch(side: str, tmp_path: Path) -> dict:
    root = tmp_path / side
    pkg = _package(root / "src")
    out = root / "out"
    out.mkdir()
    port = free_port()
    env = ros_env(port, root / "home", {"OUT_DIR": str(out)})
    if side == "debian":
        env = reference_env(env)
        shim = root / "bin"  # ROS's scripts say `#!/usr/bin/env python`: python-is-python3
        shim.mkdir()
        (shim / "python").symlink_to("/usr/bin/python3")
        env["PATH"] = f"{shim}:{env['PATH']}"
        env["ROS_PACKAGE_PATH"] = f"{root / 'src'}:/usr/share"
        argv = ["/usr/bin/roslaunch", "-p", str(port), str(pkg / "envs.launch")]
    else:
        env["ROS_PACKAGE_PATH"] = str(root / "src")
        argv = [ROSLAUNCH, "-p", str(port), str(pkg / "envs.launch")]
    proc = Proc(argv, env)
    try:
        respawned = out / "respawned"
        # exits 0 at once: respawned by roslaunch's monitor, so more than one line comes
        wait_until(lambda: respawned.exists() and len(respawned.read_text().splitlines()) >= 3,
                   timeout=40, what=f"{side}: the respawn node's third start")
        wait_until(lambda: all((out / n).exists() for n in ("first", "n1", "n2", "n3", "n4", "n5")),
                   timeout=20, what=f"{side}: every node's environment")
        time.sleep(0.5)  # nodes without respawn had their chance to run twice (they must not)
        return {p.name: p.read_text().splitlines() for p in out.iterdir()}
    finally:
        proc.stop()


def test_env_and_respawn_as_debians_roslaunch(tmp_path: Path):
    need(os.path.exists("/usr/bin/roslaunch"), "Debian's roslaunch",
         "scripts/install-ros-reference.sh")
    mine, theirs = _launch("minros", tmp_path), _launch("debian", tmp_path)
    for name in ("first", "n1", "n2", "n3", "n4", "n5"):
        assert mine[name] == theirs[name], name
        assert len(mine[name]) == 1, f"{name} (no respawn) ran {len(mine[name])} times"
    assert theirs["n4"] == ["A_TOP=top B_GROUP=None C_INC=inc D_AFTER=None ROS_NAMESPACE=None"]
    assert len(mine["respawned"]) >= 3 and len(theirs["respawned"]) >= 3
    assert set(mine["respawned"]) == set(theirs["respawned"])

