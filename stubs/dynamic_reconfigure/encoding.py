"""dynamic_reconfigure.encoding: configurations <-> messages (minros.dynamic_reconfigure.encoding)."""

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
