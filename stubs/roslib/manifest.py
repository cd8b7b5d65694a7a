"""roslib.manifest: rosbuild ``manifest.xml`` files (parsed by rospkg; minros.packages)."""

from __future__ import annotations

from typing import Any

from rospkg.manifest import InvalidManifest as ManifestException  # noqa: F401
from rospkg.manifest import Manifest  # noqa: F401

from minros.packages import MANIFEST_FILE, manifest_file, parse_manifest_file, parse_manifest_text
from minros.workspace.rosbuild import Depend, Export, ROSDep, VersionControl  # noqa: F401


def load_manifest(package: str) -> Any:
    """The parsed ``manifest.xml`` of ``package`` (InvalidROSPkgException if it has none)."""
    return parse_manifest_file(manifest_file(package))


def parse_file(file: str) -> Any:  # noqa: A002 - roslib's parameter name
    return parse_manifest_file(file)


def parse(string: str, filename: str = "string") -> Any:
    return parse_manifest_text(string, filename)


__all__ = ["MANIFEST_FILE", "Depend", "Export", "ROSDep", "VersionControl", "Manifest", "ManifestException", "load_manifest", "manifest_file",
           "parse", "parse_file"]
