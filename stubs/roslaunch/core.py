"""roslaunch.core: Node and RLException (minros.launch.api)."""

from minros.launch.api import Node, RLException  # noqa: F401
