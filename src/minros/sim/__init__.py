"""The pure parts of ``minros sim``, map_server and move_base: no sockets, no ROS messages.

* ``mapfile``: map_server's map format (a YAML file naming an image) read into an occupancy
  grid with ROS's negate, thresholds and modes, and map_saver's writer;
* ``grid``: an occupancy grid placed in the world (cell <-> metre conversions);
* ``raycast``: numpy ray casting over a distance field (every robot's laser in one batch);
* ``kinematics``: differential drive (exact arc integration, wheel angles, limits);
* ``world``: the simulated world: robots on a map, collisions, laser scans;
* ``planner``: move_base's pieces: the inflated costmap, A*, the path follower;
* ``render``: the top-down picture of the world (numpy + OpenCV drawing);
* ``robot``: the simulated robot's description (a TurtleBot3 Burger-like URDF of boxes and
  cylinders) and its fixed frames.

The ROS nodes around them live in :mod:`minros.nodes` (``minros_sim``, ``map_server``,
``move_base``) and the ``minros sim`` command in :mod:`minros.cli.sim`.
"""
