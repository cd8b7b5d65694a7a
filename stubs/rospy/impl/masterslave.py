"""rospy.impl.masterslave: the slave XML-RPC API and its argument checks
(minros.rospy_internals.masterslave). Like rospy's module, its namespace also has rospy.core's
names (``from rospy.core import *``) and the helpers it imports."""

from minros.rospy_internals import core as _core
from minros.rospy_internals.masterslave import (  # noqa: F401
    LOG_API,
    MSG,
    STATUS,
    VAL,
    ParameterInvalid,
    ROSHandler,
    apivalidate,
    is_publishers_list,
)
from minros.rospy_internals.paramserver import get_param_server_cache  # noqa: F401
from minros.rospy_internals.registration import RegManager, get_topic_manager  # noqa: F401
from minros.wire.rosapi import non_empty  # noqa: F401
from minros.wire.xmlrpc_node import XmlRpcHandler  # noqa: F401

_core.star_import(globals())
