"""mux_list: call a mux's list service (see mux_client)."""

import sys

from minros.nodes.topic_tools.mux_client import mux_list

if __name__ == "__main__":
    sys.exit(mux_list())
