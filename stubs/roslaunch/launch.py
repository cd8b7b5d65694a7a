"""roslaunch.launch: ROSLaunchRunner. This module *is* minros.launch.rosrunner (callers
replace its ``printerrlog``)."""

import sys

from minros.launch import rosrunner

sys.modules[__name__] = rosrunner
