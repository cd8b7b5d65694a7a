"""Stand-in for rosclean: the size of the ROS log files and purging them (minros.cli.clean)."""

from minros.cli.clean import (  # noqa: F401
    CleanupException,
    __version__,
    _get_check_dirs,
    _rosclean_cmd_check,
    _rosclean_cmd_purge,
    _sort_file_by_oldest,
    get_disk_usage,
    get_human_readable_disk_usage,
    rosclean_main,
)
