"""mux_delete: call a mux's delete service (see mux_client)."""

import sys

from minros.nodes.topic_tools.mux_client import mux_delete

if __name__ == "__main__":
    sys.exit(mux_delete())
