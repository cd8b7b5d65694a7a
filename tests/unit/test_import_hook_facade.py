"""Importing minros changes nothing (no import hook, no cv2 hook, no client library), so the
master and the tools run without them; ``import rospy`` installs both, as a user program needs."""

from __future__ import annotations

import subprocess
import sys

import pytest

# each test starts a process (see the slow marker in pyproject.toml)
pytestmark = pytest.mark.slow


def run(code: str, ros_package_path: str) -> subprocess.CompletedProcess:
    return subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=60,
                          env={"ROS_PACKAGE_PATH": ros_package_path, "PATH": "/usr/bin:/bin"})


def test_import_minros_has_no_side_effects(tmp_path):
    code = ("import sys\nbefore = list(sys.meta_path)\n"
            "import minros, minros.msgs, minros.master, minros.node, minros.cli.main\n"
            "from minros.msgs import get_message_class\n"
            "get_message_class('std_msgs/String')\n"
            "print(sys.meta_path == before, 'minros.client.imshow' in sys.modules,\n"
            "      'minros.client.topics' in sys.modules)\n")
    out = run(code, str(tmp_path))
    assert out.returncode == 0, out.stderr
    assert out.stdout.split() == ["True", "False", "False"]


def test_import_rospy_serves_user_packages(tmp_path):
    pkg = tmp_path / "ws" / "my_msgs"
    (pkg / "msg").mkdir(parents=True)
    (pkg / "package.xml").write_text("<package format='2'><name>my_msgs</name></package>\n")
    (pkg / "msg" / "Reading.msg").write_text("Header header\nfloat64 value\n")
    code = ("import rospy\nfrom my_msgs.msg import Reading\n"
            "print(Reading._type, Reading._has_header, Reading(value=2.5).value)\n")
    out = run(code, str(tmp_path / "ws"))
    assert out.returncode == 0, out.stderr
    assert out.stdout.split() == ["my_msgs/Reading", "True", "2.5"]
