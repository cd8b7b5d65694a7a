"""``rosbag.bag``: where ROS's Bag class and exceptions live."""

from minros.bag.bag import *  # noqa: F401,F403
from minros.bag.bag import Bag, BagMessage, BagMessageWithConnectionHeader  # noqa: F401
from minros.bag.errors import *  # noqa: F401,F403
from minros.bag.recordio import *  # noqa: F401,F403 - rosbag.bag's record helpers (_write_record, ...)
