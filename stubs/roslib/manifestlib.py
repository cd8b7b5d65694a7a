"""roslib.manifestlib: rosbuild manifests parsed field by field (minros.workspace.rosbuild)."""

from minros.workspace.rosbuild import (  # noqa: F401
    ALLOWXHTML,
    OPTIONAL,
    REQUIRED,
    VALID,
    Depend,
    Export,
    ManifestException,
    Platform,
    ROSDep,
    StackDepend,
    VersionControl,
    check,
    check_depends,
    check_exports,
    check_optional,
    check_platform,
    check_required,
    check_rosdeps,
    check_stack_depends,
    check_versioncontrol,
    get_nodes_by_name,
    parse,
    parse_file,
)
from minros.workspace.rosbuild import Manifest as _Manifest  # noqa: F401
