"""``rosrun rosbag play`` (and ``<node pkg="rosbag" type="play">``): the play program of ROS's rosbag
package, which ``rosbag play`` runs."""

import sys

from minros.cli.bag import play_node_main

if __name__ == "__main__":
    sys.exit(play_node_main())
