"""rospy.core: minros.rospy_internals.core, which *is* this module (rospy's globals here are the
node's state, read and set through the module object)."""

import sys

from minros.rospy_internals import core as _module

sys.modules[__name__] = _module
