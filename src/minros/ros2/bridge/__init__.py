"""``minros ros2``: a ROS 1 graph and a ROS 2 domain joined, as ros1_bridge joins them.

The layers (an import-linter contract in pyproject.toml), bottom up:

``config`` | ``qos`` | ``raw``   pure: parameter_bridge's YAML; how ROS 1's latching and queue
            sizes become ROS 2 QoS and back; ROS 1 classes that carry bytes under a type
``plan``     pure: which topics and services to bridge from the two graphs, ros1_bridge's
            dynamic_bridge rules (or exactly what a configuration lists)
``runtime``  the I/O: one ROS 1 node (minros's client library), one ROS 2 node
            (:mod:`minros.ros2.rmw`), the graph and control threads, the bridges, whose
            messages :mod:`minros.ros2.types` converts as bytes

``docs/ros2.md`` ("The bridge") has the rules and the limits; ``minros ros2 --help`` the
command.
"""
