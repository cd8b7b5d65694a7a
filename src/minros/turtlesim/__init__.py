"""minros's turtlesim: the simulator node and the tutorial tools of ros_tutorials/turtlesim.

Modules run with ``python -m`` (``rosrun turtlesim <name>`` maps to them): ``turtlesim_node``,
``turtle_teleop_key``, ``draw_square``, ``mimic``. :mod:`minros.turtlesim.sim` is the simulation
without ROS.
"""
