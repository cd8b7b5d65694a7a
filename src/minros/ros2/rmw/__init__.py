"""ROS 2's middleware semantics (what rmw_fastrtps and rmw_cyclonedds do) on minros's RTPS.

The layers (an import-linter contract in pyproject.toml):

``node``     Context (one DDS participant per domain, its ``ros_discovery_info`` and graph),
             Node, Publisher, Subscription; a node's services and clients come from
``service``  Service and Client, answering Fast DDS's out-of-band request identity and
             Cyclone's in-band header each in its own form
``graph``    ``ros_discovery_info``'s ParticipantEntitiesInfo codec and the graph tables
             (nodes, topics and types, endpoints with QoS and type hash), pure
``qos`` | ``names``  QoS profiles as rclpy names them; ROS 2 names and types on DDS

Payloads are serialized CDR bytes; the caller names the type and gives its RIHS01 hash.
"""

from minros.ros2.rmw.node import Context, MessageInfo, Node, Publisher, Subscription
from minros.ros2.rmw.qos import (
    DEFAULT,
    LATCHED,
    PARAMETERS,
    SENSOR_DATA,
    SERVICES_DEFAULT,
    SYSTEM_DEFAULT,
    QoSProfile,
)
from minros.ros2.rmw.service import Client, Service, ServiceTimeout

__all__ = ["Client", "Context", "DEFAULT", "LATCHED", "MessageInfo", "Node", "PARAMETERS",
           "Publisher", "QoSProfile", "SENSOR_DATA", "SERVICES_DEFAULT", "SYSTEM_DEFAULT",
           "Service", "ServiceTimeout", "Subscription"]
