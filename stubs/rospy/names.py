"""rospy.names: minros.rospy_internals.names, which *is* this module (rospy's globals here are the
node's state, read and set through the module object)."""

import sys

from minros.rospy_internals import names as _module

sys.modules[__name__] = _module
