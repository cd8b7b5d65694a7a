"""roslaunch.parent.ROSLaunchParent (roslaunch's process API over minros's process monitor)
on a machine with no master: it starts ``rosmaster --core`` and rosout as core processes, sets
the parameters and /run_id, starts the nodes, and on shutdown stops them all, the master last."""

from __future__ import annotations

import subprocess
from pathlib import Path

from support import PYTHON, free_port, ros_env

SCRIPT = r'''
import sys, time, xmlrpc.client
import roslaunch.parent, roslaunch.rlutil
uri = sys.argv[2]
parent = roslaunch.parent.ROSLaunchParent("run-parent-test", [sys.argv[1]], port=int(sys.argv[3]),
                                          show_summary=False)
parent.start()
master = xmlrpc.client.ServerProxy(uri)
deadline = time.time() + 20
while time.time() < deadline:
    nodes = [n for _t, ns in master.getSystemState("/probe")[2][0] for n in ns]
    if "/talker" in nodes and "/rosout" in nodes:
        break
    time.sleep(0.1)
print("NODES", sorted(set(nodes)))
print("PARAM", master.getParam("/probe", "/rate")[2], master.getParam("/probe", "/run_id")[2])
print("ACTIVE", sorted(n.split("-")[0] for n in parent.pm.get_active_names()))
parent.shutdown()
try:
    master.getPid("/probe")
    print("MASTER still up")
except OSError:
    print("MASTER down")
'''

LAUNCH = '''<launch>
  <param name="rate" value="5"/>
  <node pkg="rospy_tutorials" type="talker" name="talker"/>
</launch>
'''


def test_parent_starts_master_rosout_and_nodes_and_stops_them(tmp_path: Path) -> None:
    port = free_port()
    launch = tmp_path / "talker.launch"
    launch.write_text(LAUNCH)
    env = ros_env(port, tmp_path)
    run = subprocess.run([PYTHON, "-c", SCRIPT, str(launch), f"http://localhost:{port}/", str(port)],
                         env=env, capture_output=True, text=True, timeout=120)
    out = run.stdout
    assert run.returncode == 0, run.stderr[-2000:]
    assert "auto-starting new master" in out and "started core service [/rosout]" in out
    assert "NODES ['/rosout', '/talker']" in out
    assert "PARAM 5 run-parent-test" in out
    assert "ACTIVE ['master', 'rosout', 'talker']" in out
    assert "MASTER down" in out
    killed = [line.split("]")[0].lstrip("[").split("-")[0] for line in out.splitlines()
              if line.endswith("killing on exit")]
    assert killed == ["talker", "rosout", "master"]  # nodes, then the core, the master last
