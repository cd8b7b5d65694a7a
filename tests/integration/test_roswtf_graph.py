"""roswtf (minros wtf) on a live graph: an unconnected subscription, a node that died without
unregistering, and (the oracle) Debian's roswtf reporting the same online findings."""

from __future__ import annotations

import os
import re
import signal
import subprocess
from pathlib import Path

from support import PYTHON, Proc, reference_env, reference_imports, ros_env

LONELY = r'''
import rospy
from std_msgs.msg import String
rospy.init_node("lonely")
rospy.Subscriber("/nobody_publishes", String, lambda m: None)
print("ready", flush=True)
rospy.spin()
'''

DOOMED = r'''
import rospy
from std_msgs.msg import String
rospy.init_node("doomed")
pub = rospy.Publisher("/doomed_out", String, queue_size=1)
print("ready", flush=True)
rospy.spin()
'''


def online_findings(output: str) -> list:
    """The WARNING/ERROR lines (and their bullet lines) after 'Online checks summary'."""
    text = re.sub(r"\x1b\[[0-9;]*m", "", output)
    tail = text.split("Online checks summary:", 1)[1]
    return [line.strip() for line in tail.splitlines()
            if line.startswith(("WARNING", "ERROR", " *", "   *"))]


def test_roswtf_reports_a_lonely_subscriber_and_a_dead_node(minros_core: int, ros_home: Path,
                                                           tmp_path: Path):
    env = ros_env(minros_core, ros_home, {"ROS_PACKAGE_PATH": str(tmp_path)})
    (tmp_path / "lonely.py").write_text(LONELY)
    (tmp_path / "doomed.py").write_text(DOOMED)
    lonely = Proc([PYTHON, str(tmp_path / "lonely.py")], env)
    doomed = Proc([PYTHON, str(tmp_path / "doomed.py")], env)
    try:
        lonely.read_until("ready", 20)
        doomed.read_until("ready", 20)
        os.killpg(doomed.popen.pid, signal.SIGKILL)  # no chance to unregister
        doomed.popen.wait(10)
        out = subprocess.run([PYTHON, "-m", "minros", "wtf"], env=env, cwd=tmp_path,
                             capture_output=True, text=True, timeout=120)
        assert out.returncode == 0, out.stderr
        findings = online_findings(out.stdout)
        assert "WARNING The following node subscriptions are unconnected:" in findings
        assert "* /lonely:" in findings and "* /nobody_publishes" in findings
        assert "ERROR Could not contact the following nodes:" in findings and "* /doomed" in findings
        if reference_imports("roswtf"):
            ref = subprocess.run(["/usr/bin/roswtf"], env=reference_env(env), cwd=tmp_path,
                                 capture_output=True, text=True, timeout=120)
            theirs = online_findings(ref.stdout)
            for line in ("* /lonely:", "* /nobody_publishes", "* /doomed",
                         "ERROR Could not contact the following nodes:"):
                assert line in theirs, ref.stdout
    finally:
        lonely.stop()
        doomed.stop()
