"""ROS 2 from minros: the DDS wire (``rtps``), ROS 2's middleware semantics on it (``rmw``) and
ROS 2's types (``types``). Importing this package imports nothing below it."""
