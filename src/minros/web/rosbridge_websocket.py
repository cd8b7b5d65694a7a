"""``rosrun rosbridge_server rosbridge_websocket``: ``minros web`` as rosbridge's node (port 9090)."""

import sys

from minros.web.node import run_node

if __name__ == "__main__":
    sys.exit(run_node("rosbridge_websocket", 9090, "rosbridge_websocket"))
