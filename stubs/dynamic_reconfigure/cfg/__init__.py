"""dynamic_reconfigure.cfg: the package of dynamic_reconfigure's own generated configurations.
Debian's holds only TestConfig, the configuration of dynamic_reconfigure's C++ test node,
which minros does not ship; a package's own ``<pkg>.cfg.<Name>Config`` modules come from its
``.cfg`` scripts (minros.dynamic_reconfigure.cfg_import)."""
