"""``minros zenoh``: ROS 1 topics and services over Zenoh, wire-compatible with zenoh-bridge-ros1.

The pure parts import nothing outside the standard library and minros, so ``minros zenoh keys``
and the tests of the key scheme, the beacons and the bridging plan run without Zenoh:

- ``keys``      the key expressions of zenoh-plugin-ros1 (data, discovery) and minros's own
- ``discovery`` the table of remote resources heard in beacons, lost after 3 s of silence
- ``plan``      what to bridge, from the local graph and the remote resources
- ``layout``    a check that bytes are one message of a type, without building it
- ``meta``      the record a minros bridge answers about a topic (definition, latching)

``bridge`` (the running bridge) needs the ``eclipse-zenoh`` package: ``pip install minros[zenoh]``.
"""

from __future__ import annotations

import importlib.util

#: the one line a user sees when the extra is missing
MISSING_EXTRA = ("the Zenoh bridge needs the eclipse-zenoh package, which minros installs as an "
                 "extra: pip install minros[zenoh]")


def available() -> bool:
    """Whether the ``zenoh`` package (eclipse-zenoh) can be imported, without importing it."""
    try:
        return importlib.util.find_spec("zenoh") is not None
    except (ImportError, ValueError):  # a broken or None entry in sys.modules
        return False
