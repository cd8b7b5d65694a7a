"""Stand-in for rosmaster: ROS's master, which here is minros's (minros.master)."""

from .main import rosmaster_main  # noqa: F401
from .master import DEFAULT_MASTER_PORT  # noqa: F401
