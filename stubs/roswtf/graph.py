"""roswtf.graph: checks of the running graph (minros.cli.wtf)."""

from minros.cli.wtf import (  # noqa: F401
    graph_errors,
    graph_warnings,
    missing_edges,
    ping_check,
    probe_all_services,
    simtime_check,
    unconnected_subscriptions,
    unexpected_edges,
    wtf_check_graph,
)
from roswtf.context import WtfException  # noqa: E402, F401
from roswtf.environment import paths  # noqa: E402, F401
from roswtf.model import WtfError, WtfWarning  # noqa: E402, F401
from roswtf.rules import error_rule, warning_rule  # noqa: E402, F401
