"""roslib.stacks: stacks (rosbuild stacks and catkin metapackages) on the package path
(minros.workspace.rosbuild over minros's package lookup)."""

from minros.workspace.rosbuild import (  # noqa: F401
    ROS_STACK,
    STACK_FILE,
    InvalidROSStackException,
    ROSStackException,
    expand_to_packages,
    get_stack_dir,
    get_stack_version,
    get_stack_version_by_dir,
    list_stacks,
    list_stacks_by_path,
    stack_of,
)

ROS_ROOT = "ROS_ROOT"
ROS_PACKAGE_PATH = "ROS_PACKAGE_PATH"
