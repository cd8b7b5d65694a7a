"""tf.tfwtf: roswtf's tf plugin (minros.cli.tfwtf)."""

from minros.cli.tfwtf import (  # noqa: F401
    cycle_detection,
    is_tf_active,
    multiple_authority,
    no_msgs,
    not_normalized,
    reparenting,
    rostime_delta,
    roswtf_plugin_online,
    tf_errors,
    tf_warnings,
)
from roswtf.rules import error_rule, warning_rule  # noqa: E402, F401
