"""rospy.client's internals: private parameters from the command line."""

from __future__ import annotations

from typing import Any, Dict, Sequence

from minros import names as _names
from minros.exceptions import ROSInitException


def load_command_line_node_params(argv: Sequence[str]) -> Dict[str, Any]:
    """``_p:=value`` arguments -> ``{'p': value}`` (YAML-typed); ROSInitException naming a bad
    one."""
    try:
        return _names.load_command_line_node_params(argv)
    except ValueError as exc:
        raise ROSInitException(f"invalid command-line parameters: {exc}") from None
