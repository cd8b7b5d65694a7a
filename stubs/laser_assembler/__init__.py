"""laser_assembler: minros provides the package's service definitions only."""
