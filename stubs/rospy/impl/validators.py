"""rospy.impl.validators: the argument checks of the slave API (minros.wire.rosapi)."""

from minros.wire.rosapi import ParameterInvalid, non_empty  # noqa: F401
