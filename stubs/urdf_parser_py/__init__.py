"""urdf_parser_py stand-in (see minros.urdf_parser)."""
