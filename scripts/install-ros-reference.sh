#!/usr/bin/env bash
# Install Debian's ROS 1 (ros_comm 1.15.15, Noetic) for /usr/bin/python3: the reference
# implementation that minros's interoperability tests and benchmarks run against.
# Idempotent; needs root (CI runs as root). See ../shared/spec/ros1-reference.md.
set -euo pipefail
if [ "$(id -u)" -ne 0 ]; then SUDO=sudo; else SUDO=; fi
PKGS="ros-core python3-rosmaster python3-roslaunch rosout
  python3-rospy python3-rostopic python3-rosnode python3-rosparam python3-rosservice
  python3-rosbag python3-roslz4 python3-rosmsg python3-genpy python3-genmsg
  ros-std-msgs python3-std-msgs libstd-msgs-dev ros-std-srvs python3-std-srvs libstd-srvs-dev
  ros-sensor-msgs python3-sensor-msgs libsensor-msgs-dev
  ros-geometry-msgs python3-geometry-msgs libgeometry-msgs-dev
  ros-nav-msgs python3-nav-msgs ros-actionlib-msgs python3-actionlib-msgs
  ros-diagnostic-msgs python3-diagnostic-msgs ros-shape-msgs python3-shape-msgs
  ros-stereo-msgs python3-stereo-msgs ros-trajectory-msgs python3-trajectory-msgs
  ros-visualization-msgs python3-visualization-msgs ros-tf2-msgs python3-tf2-msgs
  ros-roscpp-msg python3-roscpp-msg ros-rosgraph-msgs python3-rosgraph-msgs
  python3-cv-bridge python3-numpy libroscpp-dev g++ pkg-config python3-catkin-pkg
  python3-tf2-ros python3-tf python3-tf2-geometry-msgs tf2-tools tf-tools
  python3-actionlib python3-message-filters python3-diagnostic-updater
  python3-dynamic-reconfigure libdynamic-reconfigure-config-init-mutex-dev
  python3-roslib python3-rosgraph python3-rostest python3-rosunit"
# Tools the tests drive besides ROS: a virtual display for turtlesim's window, zsh for
# devel/setup.zsh; python3-venv and python3-tk so that minros's own venv can be built on the
# same interpreter as the reference (scripts/test.sh), turtlesim's Tk window included;
# graphviz for view_frames' frames.pdf; iproute2 for the two-host tests' network namespaces;
# tshark opens the capture files `minros trace pcap` writes.
TEST_TOOLS="xvfb zsh python3-venv python3-tk graphviz iproute2 tshark"
# minros web's tests: Debian's Chromium for roslib in a real browser (Playwright drives it),
# node and npm for Foxglove's and roslib's own client libraries (tests/web/js, npm ci).
WEB_TEST_TOOLS="chromium nodejs npm"
if /usr/bin/python3 -c 'import rospy, rosmaster, genpy, std_msgs.msg, sensor_msgs.msg, tf2_msgs.msg' 2>/dev/null \
   && /usr/bin/python3 -c 'import rosbag, roslz4' 2>/dev/null && [ -x /usr/lib/rosbag/record ] \
   && /usr/bin/python3 -c 'import actionlib, message_filters, diagnostic_updater, dynamic_reconfigure.client' 2>/dev/null \
   && /usr/bin/python3 -c 'import roslib, rosgraph, rostest, rosunit, genmsg, sensor_msgs.point_cloud2' 2>/dev/null \
   && [ -x /usr/lib/genpy/genmsg_py.py ] \
   && [ -f /usr/share/dynamic_reconfigure/package.xml ] \
   && command -v rostopic >/dev/null && command -v catkin_create_pkg >/dev/null \
   && pkg-config --exists roscpp std_msgs && command -v Xvfb >/dev/null && command -v zsh >/dev/null \
   && /usr/bin/python3 -c 'import ensurepip, tkinter' 2>/dev/null \
   && /usr/bin/python3 -c 'import tf2_py, tf2_ros, tf, tf2_geometry_msgs' 2>/dev/null \
   && [ -x /usr/lib/tf/tf_echo ] && [ -x /usr/lib/tf2_tools/view_frames.py ] && command -v dot >/dev/null \
   && [ -x /usr/bin/chromium ] && command -v node >/dev/null && command -v npm >/dev/null \
   && command -v ip >/dev/null && command -v tshark >/dev/null; then
  echo "ROS 1 reference already installed"
  exit 0
fi
$SUDO apt-get update -q
# tshark's package asks whether non-root users may capture: no (and no question)
echo "wireshark-common wireshark-common/install-setuid boolean false" | $SUDO debconf-set-selections
# shellcheck disable=SC2086
DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y -q --no-install-recommends $PKGS $TEST_TOOLS $WEB_TEST_TOOLS
/usr/bin/python3 -c 'import rospy, rosmaster, genpy' && echo "ROS 1 reference installed"
