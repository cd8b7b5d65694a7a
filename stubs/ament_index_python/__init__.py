"""ament_index_python stand-in, for the libraries from PyPI that are ROS 2's releases.

PyPI's xacro 2.x (ROS's own xacro) resolves ``$(find pkg)`` through
``ament_index_python.packages.get_package_share_directory``; minros answers from its ROS 1
package lookup (ROS_PACKAGE_PATH, then the packages it bundles), where a package's folder is
what ROS 2 calls its share directory.
"""

from ament_index_python.packages import (  # noqa: F401
    PackageNotFoundError,
    get_package_prefix,
    get_package_share_directory,
)
