"""sensor_msgs.point_cloud2: PointCloud2 reading and making (minros.point_cloud2, numpy)."""

from minros.point_cloud2 import (  # noqa: F401
    create_cloud,
    create_cloud_xyz32,
    read_points,
    read_points_list,
)
from sensor_msgs.msg import PointCloud2, PointField  # noqa: F401
