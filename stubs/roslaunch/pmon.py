"""roslaunch.pmon: roslaunch's process monitor. This module *is* minros.launch.procmon
(callers read and set its globals, such as ``_shutting_down``)."""

import sys

from minros.launch import procmon

sys.modules[__name__] = procmon
