"""genpy.generate_struct: struct patterns and the pack/unpack expressions of generated code
(minros.msgs.pygen)."""

from minros.msgs.pygen import (  # noqa: F401
    SIMPLE_TYPES_DICT,
    add_pattern,
    clear_patterns,
    compute_struct_pattern,
    get_patterns,
    int32_pack,
    int32_unpack,
    pack,
    pack2,
    reduce_pattern,
    serialize,
    unpack,
    unpack2,
    unpack3,
)
