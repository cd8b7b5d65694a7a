"""bondpy stand-in: ``from bondpy import bondpy`` (see minros.bondpy)."""
