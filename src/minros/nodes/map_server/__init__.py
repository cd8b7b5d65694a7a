"""map_server's two programs: ``map_server`` (serve a map file) and ``map_saver`` (write one).

The file format and the pixel rules are :mod:`minros.sim.mapfile`.
"""
