"""``rosrun move_base move_base``: a small navigation node for teaching (see move_base.py).

Its planner, costmap and path follower are :mod:`minros.sim.planner`.
"""
