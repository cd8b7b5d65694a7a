"""camera_info_manager: a Debian rospy calibration client calls our set_camera_info; the
file we save is read back by Debian's camera_calibration_parsers (ROS's own YAML reader)
to the same CameraInfo, and our manager loads it again."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from support import PYTHON, REFERENCE_PYTHON, Proc, need, reference_env, reference_imports, ros_env

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
