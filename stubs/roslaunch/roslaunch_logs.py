"""roslaunch.roslaunch_logs: the roslaunch-logs command (minros.cli.launch_logs)."""

from minros.cli.launch_logs import NAME, get_run_id, logs_main  # noqa: F401
