"""``rosrun rosbag record`` (and ``<node pkg="rosbag" type="record">``): the record program of ROS's rosbag
package, which ``rosbag record`` runs."""

import sys

from minros.cli.bag import record_node_main

if __name__ == "__main__":
    sys.exit(record_node_main())
