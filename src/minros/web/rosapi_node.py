"""``rosrun rosapi rosapi_node``: only the rosapi services, for launch files that start rosapi on
its own (``minros web`` and the rosbridge node serve them already)."""

import sys

from minros.web.node import run_node

if __name__ == "__main__":
    sys.exit(run_node("rosapi", 0, "rosapi", serve=False))
