"""PyKDL stand-in: Orocos KDL's Python API in pure Python (behaviour in minros.kdl)."""

from minros.kdl import *  # noqa: F403
from minros.kdl import __all__, __version__  # noqa: F401
