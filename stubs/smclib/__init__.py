"""smclib stand-in (see minros.smclib)."""
