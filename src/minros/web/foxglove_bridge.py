"""``rosrun foxglove_bridge foxglove_bridge``: ``minros web`` as foxglove_bridge's node (port 8765)."""

import sys

from minros.web.node import run_node

if __name__ == "__main__":
    sys.exit(run_node("foxglove_bridge", 8765, "foxglove_bridge"))
