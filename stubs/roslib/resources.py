"""roslib.resources: the files in a package's resource folder (minros.packages)."""

from minros.packages import (  # noqa: F401
    list_package_resources,
    list_package_resources_by_dir,
)
