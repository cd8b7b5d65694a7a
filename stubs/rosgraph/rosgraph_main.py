"""rosgraph.rosgraph_main: the rosgraph command (minros.cli.rosgraph)."""

from minros.cli.rosgraph import fullusage, rosgraph_main  # noqa: F401

from . import masterapi, roslogging  # noqa: F401 - rosgraph.rosgraph_main imports them
from .impl import graph  # noqa: F401
