"""A camera's CameraInfo (latched) and a robot status of a message type nobody installed
(my_robot_msgs/Status, from its definition), at 10 Hz until stopped: what the ROS 2
conversion tests record beside ``minros sim`` and turtlesim. A plain rospy script."""

import sys
from pathlib import Path

import rospy
from sensor_msgs.msg import CameraInfo

sys.path.insert(0, str(Path(__file__).resolve().parent.parent))
from ros2bag_support import CUSTOM_TYPE, custom_classes  # noqa: E402

classes = custom_classes()
Status, Wheel = classes[CUSTOM_TYPE], classes["my_robot_msgs/Wheel"]

rospy.init_node("camera_and_status")
info_pub = rospy.Publisher("/camera/camera_info", CameraInfo, queue_size=10, latch=True)
status_pub = rospy.Publisher("/status", Status, queue_size=10)
print("READY", flush=True)
rate = rospy.Rate(10)
i = 0
while not rospy.is_shutdown():
    now = rospy.Time.now()
    info = CameraInfo(height=480, width=640, distortion_model="plumb_bob")
    info.header.stamp, info.header.frame_id = now, "camera_optical"
    info.D = [0.05, -0.1, 0.001, 0.0005, 0.0]
    info.K = [525.0, 0.0, 319.5, 0.0, 525.0, 239.5, 0.0, 0.0, 1.0]
    info.R = [1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0]
    info.P = [525.0, 0.0, 319.5, 0.0, 0.0, 525.0, 239.5, 0.0, 0.0, 0.0, 1.0, 0.0]
    info_pub.publish(info)
    status = Status(Mode=i % 2, Name="robot", blob=[i % 128, -1], letter=65 + i % 26,
                    last_seen=now, uptime=rospy.Duration(i, 500),
                    wheels=[Wheel(Speed=0.1 * i, id=-1), Wheel(Speed=-0.1 * i, id=1)],
                    temperatures=[20.0 + i, 21.5])
    status.header.stamp, status.header.frame_id = now, "base_link"
    status_pub.publish(status)
    i += 1
    rate.sleep()
