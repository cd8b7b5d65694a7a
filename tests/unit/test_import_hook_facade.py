"""`import minros` alone (no rospy, no minros.msgs) makes user message packages importable."""

from __future__ import annotations

import subprocess
import sys


def test_import_minros_serves_user_packages(tmp_path):
    pkg = tmp_path / "ws" / "my_msgs"
    (pkg / "msg").mkdir(parents=True)
    (pkg / "package.xml").write_text("<package format='2'><name>my_msgs</name></package>\n")
    (pkg / "msg" / "Reading.msg").write_text("Header header\nfloat64 value\n")
    code = ("import minros\nfrom my_msgs.msg import Reading\n"
            "print(Reading._type, Reading._has_header, Reading(value=2.5).value)\n")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=60,
                         env={"ROS_PACKAGE_PATH": str(tmp_path / "ws"), "PATH": "/usr/bin:/bin"})
    assert out.returncode == 0, out.stderr
    assert out.stdout.split() == ["my_msgs/Reading", "True", "2.5"]
