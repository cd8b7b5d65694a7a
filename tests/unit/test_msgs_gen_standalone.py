"""What ``minros msg gen TYPE`` prints runs on its own, for every bundled type: a learner can
save it as a file and run it (explicit imports, no names injected by the registry)."""

from __future__ import annotations

import subprocess
import sys
import textwrap

import pytest

from minros.msgs import registry
from minros.msgs.testing import bundled_types

# each test starts a process (see the slow marker in pyproject.toml)
pytestmark = pytest.mark.slow


def test_every_bundled_type_runs_as_its_own_module(tmp_path):
    types = bundled_types()
    assert len(types) > 150
    for index, type_name in enumerate(types):
        source = registry.REGISTRY.source(type_name)
        origin = source.splitlines()[0].rpartition(" from ")[2]  # pkg/msg/Name.msg, no local path
        assert origin.startswith(type_name.split("/")[0] + "/") and origin.count("/") == 2, origin
        assert "import *" not in source
        (tmp_path / f"m{index}.py").write_text(source)
    # one interpreter runs every file as __main__ with fresh globals, as `python m.py` would
    script = textwrap.dedent(f"""
        import runpy, sys
        for i in range({len(types)}):
            ns = runpy.run_path(r"{tmp_path}/m%d.py" % i, run_name="__main__")
            assert "_load" not in ns or ns["_load"].__module__ == "minros.msgs.registry"
        print("all ran")
    """)
    done = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True, timeout=120)
    assert done.returncode == 0, done.stderr
    assert done.stdout.strip() == "all ran"


def test_printed_class_round_trips_when_run_as_a_file(tmp_path):
    printed = subprocess.run([sys.executable, "-m", "minros", "msg", "gen", "geometry_msgs/PoseStamped"],
                             capture_output=True, text=True, timeout=60)
    assert printed.returncode == 0, printed.stderr
    first = printed.stdout.splitlines()[0]
    assert first.endswith("from geometry_msgs/msg/PoseStamped.msg.")
    module = tmp_path / "m.py"
    module.write_text(printed.stdout + textwrap.dedent("""
        msg = PoseStamped()
        msg.header.frame_id = "map"
        msg.pose.position.x = 1.5
        data = msg.serialize_to_bytes()
        back = PoseStamped().deserialize(data)
        print(back.header.frame_id, back.pose.position.x, len(data))
    """))
    run = subprocess.run([sys.executable, str(module)], capture_output=True, text=True, timeout=60)
    assert run.returncode == 0, run.stderr
    assert run.stdout.split() == ["map", "1.5", str(len(PoseStampedBytes()))]


def PoseStampedBytes() -> bytes:  # noqa: N802 - the expected wire size, from the registry's class
    from geometry_msgs.msg import PoseStamped

    msg = PoseStamped()
    msg.header.frame_id = "map"
    msg.pose.position.x = 1.5
    return msg.serialize_to_bytes()
