"""roslib.srvs: minros.msgs.rosbuild.srvs, which *is* this module (callers set and read its
globals, e.g. ``roslib.msgs._initialized``, so they must have one home)."""

import sys

from minros.msgs.rosbuild import srvs as _module

sys.modules[__name__] = _module
