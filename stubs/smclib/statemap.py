"""smclib.statemap stand-in (see minros.smclib.statemap)."""

from minros.smclib.statemap import *  # noqa: F401,F403
