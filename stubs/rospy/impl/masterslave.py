"""rospy.impl.masterslave: the slave XML-RPC API and its argument checks (minros.rospy_internals.masterslave)."""

from minros.rospy_internals.masterslave import (  # noqa: F401
    ParameterInvalid,
    ROSHandler,
    apivalidate,
    is_publishers_list,
)
