"""diagnostic_updater stand-in: diagnostics publishing served by minros.diagnostic_updater."""

import http.client as httplib  # noqa: F401 - exported, as ROS's modules export their imports
import threading  # noqa: F401

import rospy  # noqa: F401
from minros.diagnostic_updater import *  # noqa: F401,F403
from minros.diagnostic_updater import __all__ as _names

#: what ROS's ``from diagnostic_updater import *`` gives: the library, the messages, and the
#: modules its files import without an __all__ (``rospy.init_node`` works after it)
__all__ = [*_names, "httplib", "rospy", "threading"]
