"""tf2_sensor_msgs stand-in: importing it registers sensor_msgs/PointCloud2 with tf2_ros (see
minros.tf.cloud_transforms)."""

from .tf2_sensor_msgs import *  # noqa: F403
