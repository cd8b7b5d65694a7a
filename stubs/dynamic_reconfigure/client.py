"""dynamic_reconfigure.client: Client (minros.dynamic_reconfigure.client)."""

from dynamic_reconfigure import (  # noqa: F401
    DynamicReconfigureCallbackException,
    DynamicReconfigureParameterException,
)
from dynamic_reconfigure.encoding import (  # noqa: F401
    decode_config,
    decode_description,
    encode_config,
    extract_params,
)
from dynamic_reconfigure.msg import Config as ConfigMsg  # noqa: F401
from dynamic_reconfigure.msg import ConfigDescription as ConfigDescrMsg  # noqa: F401
from dynamic_reconfigure.srv import Reconfigure as ReconfigureSrv  # noqa: F401
from minros.dynamic_reconfigure.client import Client  # noqa: F401
from minros.exceptions import ServiceException  # noqa: F401
