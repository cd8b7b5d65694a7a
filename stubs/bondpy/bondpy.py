"""bondpy.bondpy stand-in: Bond and Timeout (see minros.bondpy)."""

from minros.bondpy.bond import *  # noqa: F401,F403
