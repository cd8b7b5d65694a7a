"""``rosrun minros_sim sim_node``: the 2D simulator node behind ``minros sim``.

The simulation itself is :mod:`minros.sim` (no ROS); this package is its ROS face.
"""
