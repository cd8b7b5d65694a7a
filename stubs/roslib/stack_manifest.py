"""roslib.stack_manifest: rosbuild ``stack.xml`` files (minros.workspace.rosbuild)."""

from minros.workspace.rosbuild import (  # noqa: F401
    STACK_FILE,
    ManifestException,
    StackDepend,
    StackManifest,
    stack_file,
)
from minros.workspace.rosbuild import parse_stack as parse  # noqa: F401
from minros.workspace.rosbuild import parse_stack_file as parse_file  # noqa: F401
