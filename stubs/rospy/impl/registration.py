"""rospy.impl.registration: minros.rospy_internals.registration, which *is* this module
(callers replace its globals: the managers, ``is_shutdown``)."""

import sys

from minros.rospy_internals import registration as _module

sys.modules[__name__] = _module
