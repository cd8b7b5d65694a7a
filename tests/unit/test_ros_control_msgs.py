"""ros_control's message packages robot code imports (controller_manager_msgs, control_toolbox's
service, four_wheel_steering_msgs of ros_controllers), which Debian does not package: their
definitions are upstream's at the tags COPYRIGHT names; these md5 sums are what Debian's
genmsg computes from the same files (tests/interop/test_msg_packages.py checks all of them)."""

from __future__ import annotations

import subprocess

import pytest

from support import PYTHON

MD5 = {
    "controller_manager_msgs/SwitchController": "b29a7abc673b2c54c14b54e50f8d06a5",
    "controller_manager_msgs/ListControllers": "1341feb2e63fa791f855565d0da950d8",
    "controller_manager_msgs/LoadController": "647e5c54b8d6468952d8d31f1efe96c0",
    "controller_manager_msgs/ControllerState": "aeb6b261d97793ab74099a3740245272",
    "control_toolbox/SetPidGains": "4a43159879643e60937bf2893b633607",
    "four_wheel_steering_msgs/FourWheelSteeringStamped": "9226582df815bc6df9e3206bc05923af",
}


@pytest.mark.parametrize("type_name", sorted(MD5))
def test_md5_sums(type_name: str) -> None:
    from minros.msgs import get_message_class, get_service_class

    package, name = type_name.split("/")
    try:
        cls = get_service_class(type_name)
    except Exception:  # noqa: BLE001 - a message type, then
        cls = get_message_class(type_name)
    assert (cls._type, cls._md5sum) == (type_name, MD5[type_name])


def test_a_controller_switch_as_robot_code_writes_it() -> None:
    """Imported before rospy (the stand-ins), in a fresh interpreter, as a node's first lines."""
    code = ("from controller_manager_msgs.srv import SwitchController, SwitchControllerRequest\n"
            "from controller_manager_msgs.msg import ControllerState\n"
            "from control_toolbox.srv import SetPidGains\n"
            "from four_wheel_steering_msgs.msg import FourWheelSteering\n"
            "import rospy\n"
            "req = SwitchControllerRequest(start_controllers=['arm'], stop_controllers=[],\n"
            "                              strictness=SwitchControllerRequest.STRICT,\n"
            "                              start_asap=True, timeout=1.5)\n"
            "import io\nb = io.BytesIO(); req.serialize(b)\n"
            "back = SwitchControllerRequest().deserialize(b.getvalue())\n"
            "print(back.start_controllers, back.strictness, back.start_asap, back.timeout,\n"
            "      SwitchControllerRequest.BEST_EFFORT, FourWheelSteering().front_steering_angle)\n")
    out = subprocess.run([PYTHON, "-c", code], capture_output=True, text=True, timeout=60)
    assert out.returncode == 0, out.stderr
    assert out.stdout.split() == ["['arm']", "2", "True", "1.5", "1", "0.0"]
