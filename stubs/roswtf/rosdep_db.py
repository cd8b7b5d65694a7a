"""roswtf.rosdep_db: is rosdep's database there (minros.cli.wtfsource)."""

from minros.cli.wtfsource import get_user_home_directory, rosdep_database_updated_check  # noqa: F401
from minros.cli.wtfsource import rosdep_errors as errors  # noqa: F401
from minros.cli.wtfsource import rosdep_warnings as warnings  # noqa: F401
from minros.cli.wtfsource import wtf_check_rosdep as wtf_check  # noqa: F401
