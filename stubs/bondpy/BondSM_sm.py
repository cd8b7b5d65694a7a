"""bondpy.BondSM_sm stand-in: the bond state machine's SMC classes (see minros.bondpy.sm)."""

from minros.bondpy.sm import *  # noqa: F401,F403
