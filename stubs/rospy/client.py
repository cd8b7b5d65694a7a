"""rospy.client: node life-cycle functions (minros.client.init, minros.node, minros.client.topics)."""

from minros.client.init import init_node  # noqa: F401
from minros.client.msproxy import get_master  # noqa: F401
from minros.client.topics import get_published_topics, wait_for_message  # noqa: F401
from minros.node import myargv, on_shutdown, spin  # noqa: F401
from minros.rospy_internals.client import load_command_line_node_params  # noqa: F401, E402
