"""rostest against Debian's rostest: the same .test files (rospy test nodes run by each side's
interpreter) give the same console output: the log and results lines, the run's own test case,
rosunit's summary (SUMMARY, RESULT: SUCCESS|FAIL, the counts), and the same exit status."""

from __future__ import annotations

import re
import subprocess
from pathlib import Path

import pytest

from support import PYTHON, reference_env, require_reference, ros_env

pytestmark = pytest.mark.interop

PKGS = Path(__file__).resolve().parent.parent / "integration" / "rostest_pkgs"


def _rostest(home: Path, test: str, ours: bool) -> tuple:
    env = ros_env(None, home, {"ROS_PACKAGE_PATH": str(PKGS) + ("" if ours else ":/usr/share")})
    env.pop("ROS_MASTER_URI", None)
    argv = [PYTHON, "-m", "minros", "test"] if ours else ["/usr/bin/rostest"]
    done = subprocess.run([*argv, "rostest_demo", test], env=env if ours else reference_env(env),
                          capture_output=True, text=True, timeout=120)
    text = done.stdout.replace(str(home), "<home>")
    text = re.sub(r"rostest-[^/\s]+-\d+\.log", "rostest-HOST-PID.log", text)
    # a failure's text is the test node's own traceback (its interpreter's, its file lines)
    text = re.sub(r"(\]\[FAILURE\]-*\n).*?\n(-{80}\n)", r"\1<failure>\n\2", text, flags=re.S)
    return done.returncode, text


@pytest.mark.parametrize("test,status", [("counter.test", 0), ("fails.test", 2)])
def test_rostest_prints_what_ros1s_prints(test: str, status: int, tmp_path: Path) -> None:
    require_reference()
    ours = _rostest(tmp_path / "ours", test, ours=True)
    theirs = _rostest(tmp_path / "theirs", test, ours=False)
    assert ours == theirs
    assert theirs[0] == status
    assert "\nSUMMARY\n" in theirs[1]
    assert (" * RESULT: SUCCESS" if status == 0 else " * RESULT: FAIL") in theirs[1]
