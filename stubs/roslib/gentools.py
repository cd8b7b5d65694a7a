"""roslib.gentools: minros.msgs.rosbuild.gentools, which *is* this module (callers set and read its
globals, e.g. ``roslib.msgs._initialized``, so they must have one home)."""

import sys

from minros.msgs.rosbuild import gentools as _module

sys.modules[__name__] = _module
