"""camera_info_manager: a Debian rospy calibration client calls our set_camera_info; the
file we save is read back by Debian's camera_calibration_parsers (ROS's own YAML reader)
to the same CameraInfo, and our manager loads it again."""

from __future__ import annotations

import json
import subprocess
from pathlib import Path

import pytest

from support import (
    PYTHON,
    REFERENCE_PYTHON,
    Proc,
    need,
    reference_env,
    reference_imports,
    require_reference,
    ros_env,
)

pytestmark = pytest.mark.interop

DRIVER = r'''
import sys
import rospy
from camera_info_manager import CameraInfoManager
rospy.init_node("camera_driver")
manager = CameraInfoManager("front_cam", "file://" + sys.argv[1] + "/${NAME}.yaml", "front/")
manager.loadCameraInfo()
print("calibrated before:", manager.isCalibrated(), flush=True)
print("driver ready", flush=True)
while not rospy.is_shutdown() and not manager.isCalibrated():
    rospy.sleep(0.05)
again = CameraInfoManager("front_cam", "file://" + sys.argv[1] + "/${NAME}.yaml", "again/")
again.loadCameraInfo()
info = again.getCameraInfo()
print("reloaded", list(info.K), info.width, info.distortion_model, flush=True)
# the handler marks the manager calibrated before its answer is sent: stay up to send it
rospy.spin()
'''

CALIBRATOR = r'''
import json, sys
import rospy
from sensor_msgs.msg import CameraInfo
from sensor_msgs.srv import SetCameraInfo
import camera_calibration_parsers
rospy.wait_for_service("/front/set_camera_info", 30)
info = CameraInfo(width=640, height=480, distortion_model="plumb_bob",
                  D=[0.1, -0.2, 0.001, 0.002, 0.0],
                  K=[500.0, 0, 320.5, 0, 501.0, 240.5, 0, 0, 1],
                  R=[1.0, 0, 0, 0, 1, 0, 0, 0, 1],
                  P=[500.0, 0, 320.5, 0, 0, 501.0, 240.5, 0, 0, 0, 1, 0])
answer = rospy.ServiceProxy("/front/set_camera_info", SetCameraInfo)(info)
name, read = camera_calibration_parsers.readCalibration(sys.argv[1] + "/front_cam.yaml")
print("RESULT " + json.dumps({"success": answer.success, "name": name,
      "same": [list(read.K) == list(info.K), list(read.D) == list(info.D),
               list(read.P) == list(info.P), list(read.R) == list(info.R),
               read.width == 640, read.height == 480, read.distortion_model == "plumb_bob"]}),
      flush=True)
'''


def test_calibration_saved_by_minros_reads_in_ros(tmp_path: Path, debian_rosmaster: int,
                                                  ros_home: Path) -> None:
    need(reference_imports("camera_calibration_parsers"),
         "Debian's python3-camera-calibration-parsers is not installed",
         "scripts/install-ros-reference.sh")
    env = ros_env(debian_rosmaster, ros_home)
    driver_script = tmp_path / "driver.py"
    driver_script.write_text(DRIVER)
    calibrator_script = tmp_path / "calibrator.py"
    calibrator_script.write_text(CALIBRATOR)
    folder = tmp_path / "calib"
    driver = Proc([PYTHON, str(driver_script), str(folder)], env)
    calibrator = None
    try:
        out = driver.read_until("driver ready", 30)
        assert "calibrated before: False" in out  # no file yet: an empty calibration
        calibrator = Proc([REFERENCE_PYTHON, str(calibrator_script), str(folder)],
                          reference_env(env))
        result = json.loads(calibrator.read_until("RESULT ", 60).split("RESULT ", 1)[1]
                            .splitlines()[0])
        assert result == {"success": True, "name": "front_cam", "same": [True] * 7}, result
        out = driver.read_until("reloaded", 30)
        assert "reloaded [500.0, 0.0, 320.5, 0.0, 501.0, 240.5, 0.0, 0.0, 1.0] 640 plumb_bob" in out
    finally:
        if calibrator is not None:
            calibrator.stop()
        driver.stop()


CALIBRATIONS = {
    "cam.ini": """# Camera intrinsics

[image]

width
640

height
480

[narrow stereo]

camera matrix
430.15 0.00000 311.71
0.00000 430.53 221.06
0.00000 0.00000 1.00000

distortion
-0.33758 0.11161 0.00000 0.00000 0.00000

rectification
1.00000 0.00000 0.00000
0.00000 1.00000 0.00000
0.00000 0.00000 1.00000

projection
359.4 0.0 312.6 0.0
0.0 387.2 221.3 0.0
0.0 0.0 1.0 0.0
""",
    "ext.INI": "[image] width 2 height 3 [externals] translation 1 2 3 rotation 4 5 6\n"
               "[c] camera matrix 1 2 3 4 5 6 7 8 9 distortion 1 2 3 4 5 6 7 8\n"
               "rectification 1 0 0 0 1 0 0 0 1 projection 1e-3 -.5 +2. 123.456e2 0.1 0.7 3.3 1.23456789 9.87e-7 10 11 1.5e1\n",
    "short.ini": "[image] width 2 height 3 [c] camera matrix 1 2 3",
    "named.yaml": "image_width: 4\nimage_height: 2\ncamera_name: front\ncamera_matrix:\n"
                  "  rows: 3\n  cols: 3\n  data: [1, 0, 2, 0, 1, 3, 0, 0, 1]\n"
                  "distortion_model: rational_polynomial\ndistortion_coefficients:\n"
                  "  rows: 1\n  cols: 8\n  data: [1, 2, 3, 4, 5, 6, 7, 8]\n"
                  "rectification_matrix:\n  rows: 3\n  cols: 3\n  data: [1, 0, 0, 0, 1, 0, 0, 0, 1]\n"
                  "projection_matrix:\n  rows: 3\n  cols: 4\n  data: [1, 0, 2, 0, 0, 1, 3, 0, 0, 0, 1, 0]\n",
    "unnamed.yml": "image_width: 4\nimage_height: 2\ncamera_matrix: {rows: 3, cols: 3, data: [1, 0, 2, 0, 1, 3, 0, 0, 1]}\n"
                   "distortion_coefficients: {rows: 1, cols: 5, data: [0.1, 0, 0, 0, 0]}\n"
                   "rectification_matrix: {rows: 3, cols: 3, data: [1, 0, 0, 0, 1, 0, 0, 0, 1]}\n"
                   "projection_matrix: {rows: 3, cols: 4, data: [1, 0, 2, 0, 0, 1, 3, 0, 0, 0, 1, 0]}\n",
    "broken.yaml": "image_width: [\n",
    "cam.txt": "width 3\n",
}

READ_SCRIPT = r'''
import json, sys
import camera_calibration_parsers as ccp
out = {}
for name in sorted(sys.argv[2:]):
    found = ccp.readCalibration(sys.argv[1] + "/" + name)
    if found is None:
        out[name] = None
    else:
        cname, info = found
        out[name] = [cname, info.width, info.height, list(info.K), info.distortion_model,
                     list(info.D), list(info.R), list(info.P), type(info).__name__]
out["missing.yaml"] = ccp.readCalibration(sys.argv[1] + "/missing.yaml")
print(json.dumps(out, sort_keys=True))
'''


def test_camera_calibration_parsers_read_as_debians(tmp_path: Path) -> None:
    """readCalibration reads YAML and Videre INI files (externals, 8 coefficients, comments,
    upper-case extensions) into the CameraInfo Debian's C++ parsers make, and answers None
    where they fail."""
    for name, text in CALIBRATIONS.items():
        (tmp_path / name).write_text(text)
    args = [str(tmp_path), *CALIBRATIONS]
    ours = subprocess.run([PYTHON, "-c", READ_SCRIPT, *args], capture_output=True, text=True,
                          timeout=60)
    assert ours.returncode == 0, ours.stderr
    mine = json.loads(ours.stdout)
    assert mine["cam.ini"][:3] == ["narrow stereo", 640, 480]
    assert mine["cam.ini"][4] == "plumb_bob" and mine["unnamed.yml"][0] == "unknown"
    assert mine["short.ini"] is None and mine["cam.txt"] is None and mine["broken.yaml"] is None
    require_reference()
    theirs = subprocess.run([REFERENCE_PYTHON, "-c", READ_SCRIPT, *args], env=reference_env({}),
                            capture_output=True, text=True, timeout=60)
    assert theirs.returncode == 0, theirs.stderr
    assert mine == json.loads(theirs.stdout.strip().splitlines()[-1])
