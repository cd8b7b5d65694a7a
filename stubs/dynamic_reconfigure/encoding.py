"""dynamic_reconfigure.encoding: configurations <-> messages (minros.dynamic_reconfigure.encoding)."""

from dynamic_reconfigure.msg import (  # noqa: F401 - the messages configurations travel in
    BoolParameter,
    DoubleParameter,
    GroupState,
    IntParameter,
    ParamDescription,
    StrParameter,
)
from dynamic_reconfigure.msg import Config as ConfigMsg  # noqa: F401
from dynamic_reconfigure.msg import ConfigDescription as ConfigDescrMsg  # noqa: F401
from dynamic_reconfigure.msg import Group as GroupMsg  # noqa: F401
from minros.dynamic_reconfigure.encoding import (  # noqa: F401
    Config,
    decode_config,
    decode_description,
    encode_config,
    encode_description,
    encode_groups,
    extract_params,
    get_parents,
    get_tree,
    group_dict,
    initial_config,
)
