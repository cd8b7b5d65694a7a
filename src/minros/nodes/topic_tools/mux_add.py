"""mux_add: call a mux's add service (see mux_client)."""

import sys

from minros.nodes.topic_tools.mux_client import mux_add

if __name__ == "__main__":
    sys.exit(mux_add())
