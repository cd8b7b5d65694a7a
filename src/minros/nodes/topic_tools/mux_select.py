"""mux_select: call a mux's select service (see mux_client)."""

import sys

from minros.nodes.topic_tools.mux_client import mux_select

if __name__ == "__main__":
    sys.exit(mux_select())
