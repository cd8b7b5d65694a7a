"""``rosbag.bag``: where ROS's Bag class and exceptions live."""

import importlib.util

from minros.bag.bag import *  # noqa: F401,F403
from minros.bag.bag import Bag, BagMessage, BagMessageWithConnectionHeader  # noqa: F401
from minros.bag.errors import *  # noqa: F401,F403
from minros.bag.recordio import *  # noqa: F401,F403 - rosbag.bag's record helpers (_write_record, ...)

#: whether bags can be written and read with LZ4 compression here (the lz4 package is installed)
found_lz4 = importlib.util.find_spec("lz4") is not None
