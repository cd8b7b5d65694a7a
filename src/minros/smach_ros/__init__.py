"""smach_ros: smach states that talk ROS, and the ROS side of a state machine.

* ``SimpleActionState`` (an actionlib goal as a state), ``ServiceState`` (a service call),
  ``MonitorState`` (a topic checked message by message), ``ConditionState`` (a polled
  condition);
* ``ActionServerWrapper``: a state machine offered as an action server;
* ``IntrospectionServer``: the ``<server>/smach/container_status|_structure|_init`` topics
  smach_viewer reads and writes, and ``IntrospectionClient``;
* ``set_preempt_handler``: preempt a state machine when the node shuts down.

Importing it routes smach's log output to rospy's loggers and its shutdown check to
``rospy.is_shutdown``, as ROS's smach_ros does.
"""

import minros
from minros import smach

smach.set_loggers(minros.loginfo, minros.logwarn, minros.logdebug, minros.logerr)
smach.set_shutdown_check(minros.is_shutdown)

from minros.smach_ros.action_server_wrapper import ActionServerWrapper  # noqa: E402
from minros.smach_ros.condition_state import ConditionState  # noqa: E402
from minros.smach_ros.introspection import IntrospectionClient, IntrospectionServer  # noqa: E402
from minros.smach_ros.monitor_state import MonitorState  # noqa: E402
from minros.smach_ros.service_state import ServiceState  # noqa: E402
from minros.smach_ros.simple_action_state import SimpleActionState  # noqa: E402
from minros.smach_ros.util import set_preempt_handler  # noqa: E402

__all__ = ["set_preempt_handler", "ActionServerWrapper", "IntrospectionClient",
           "IntrospectionServer", "SimpleActionState", "ServiceState", "MonitorState",
           "ConditionState"]
