"""diagnostic_updater stand-in: diagnostics publishing served by minros.diagnostic_updater.

``from diagnostic_updater import *`` also gives what ROS's star import gives, since its
modules have no ``__all__``: the message classes and the modules they import (tests use
``DiagnosticStatus`` that way)."""

import http.client as httplib  # noqa: F401
import threading  # noqa: F401

import rospy  # noqa: F401
from diagnostic_msgs.msg import DiagnosticArray, DiagnosticStatus, KeyValue  # noqa: F401
from minros.diagnostic_updater import *  # noqa: F401,F403
from minros.diagnostic_updater import __all__ as _minros_all

__all__ = [*_minros_all, "DiagnosticArray", "DiagnosticStatus", "KeyValue", "httplib", "rospy",
           "threading"]
