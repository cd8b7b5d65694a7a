"""Stand-in for roswtf: checks of the ROS environment and the running graph (minros.cli.wtf)."""

from minros.cli.wtf import print_results, roswtf_main  # noqa: F401
