"""rosgraph.roslogging: Python logging configured the ROS way (minros.roslogging)."""

from minros.roslogging import (  # noqa: F401
    LoggingException,
    RospyLogger,
    RosStreamHandler,
    configure_logging,
    makedirs_with_parent_perms,
    renew_latest_logdir,
)

ROS_LOG_DIR = "ROS_LOG_DIR"
