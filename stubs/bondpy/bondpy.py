"""bondpy.bondpy stand-in: Bond and Timeout (see minros.bondpy)."""

from bond.msg import Constants, Status  # noqa: F401 - the bond protocol's messages
from minros.bondpy.bond import *  # noqa: F401,F403
