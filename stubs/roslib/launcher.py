"""roslib.launcher: load_manifest (minros.packages)."""

from __future__ import annotations

import sys

from minros import packages


def load_manifest(package_name: str, bootstrap_version: str = "0.7") -> None:
    """Check that the package exists (rospkg.ResourceNotFound if not); a rosbuild package's
    python folders go on sys.path."""
    sys.path[:0] = packages.load_manifest(package_name)


def get_depends(package: str, rospack) -> list:  # noqa: ANN001
    return rospack.get_depends(package, implicit=True)
