"""dynamic_reconfigure.server: Server (minros.dynamic_reconfigure.server)."""

from dynamic_reconfigure import DynamicReconfigureCallbackException  # noqa: F401
from dynamic_reconfigure.encoding import (  # noqa: F401
    decode_config,
    encode_config,
    encode_description,
    extract_params,
    get_tree,
    initial_config,
)
from dynamic_reconfigure.msg import Config as ConfigMsg  # noqa: F401
from dynamic_reconfigure.msg import ConfigDescription as ConfigDescrMsg  # noqa: F401
from dynamic_reconfigure.srv import Reconfigure as ReconfigureSrv  # noqa: F401
from minros.dynamic_reconfigure.server import Server  # noqa: F401
