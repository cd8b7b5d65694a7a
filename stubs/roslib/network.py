"""roslib.network: rosgraph.network's helpers."""

from rosgraph.network import *  # noqa: F401, F403
from rosgraph.network import (  # noqa: F401
    decode_ros_handshake_header,
    encode_ros_handshake_header,
    read_ros_handshake_header,
    write_ros_handshake_header,
)

ROS_HOSTNAME = "ROS_HOSTNAME"
ROS_IP = "ROS_IP"
SIOCGIFADDR = 35093
SIOCGIFCONF = 35090
python3 = 1
