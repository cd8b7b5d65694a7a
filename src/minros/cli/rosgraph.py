"""``rosgraph``: the ROS computation graph as text, refreshed every second until Ctrl-C.

As ROS's rosgraph: each node with the peers of its live connections (``Inbound:`` the nodes
it receives from, ``Outbound:`` the nodes it sends to), then the services; ``empty`` when the
master knows of no node and no service. The graph is rosgraph.impl.graph's (minros.tools.graph:
the master's system state and every node's bus info, each call bounded). ``--once`` (minros's
addition) prints it once and exits, for scripts.
"""

from __future__ import annotations

import sys
import threading
from typing import Any, List, Optional, TextIO

USAGE = """rosgraph is a command-line tool for debugging the ROS Computation Graph.

Usage:
\trosgraph
"""


def fullusage() -> None:
    """rosgraph's usage text."""
    print(USAGE)


def format_graph(graph: Any) -> str:
    """One refresh of rosgraph's output for a :class:`minros.tools.graph.Graph`."""
    lines: List[str] = []
    if not graph.nn_nodes and not graph.srvs:
        lines.append("empty")
    else:
        lines.append("\n")
    if graph.nn_nodes:
        lines.append("Nodes:")
        by_end, by_start = graph.nn_edges.edges_by_end, graph.nn_edges.edges_by_start
        for node in sorted(graph.nn_nodes):
            prefix = node + "|"
            lines += [f"  {node} :", "    Inbound:"]
            lines += [f"      {e.start}" for key in sorted(by_end) if key.startswith(prefix)
                      for e in by_end[key]]
            lines.append("    Outbound:")
            lines += [f"      {e.end}" for key in sorted(by_start) if key.startswith(prefix)
                      for e in by_start[key]]
    if graph.srvs:
        lines.append("Services:")
        lines += [f"  {s}" for s in sorted(graph.srvs)]
    return "\n".join(lines) + "\n"


def main(argv: List[str], prog: str = "rosgraph", out: Optional[TextIO] = None,
         stop: Optional[threading.Event] = None) -> int:
    out = out or sys.stdout
    once = False
    if argv == ["--once"]:
        once = True
    elif argv in (["-h"], ["--help"]):
        print(USAGE, file=out)
        print("\t(minros: --once prints the graph once and exits)", file=out)
        return 0
    elif argv:
        print(USAGE, file=out)
        return 255  # ROS's sys.exit(-1)
    from minros.roslogging import configure_logging
    from minros.tools.graph import Graph
    from minros.tools.master import Master, MasterException

    configure_logging("rosgraph")
    try:
        Master("/rosgraph", timeout=3.0).getPid()
    except (MasterException, OSError):
        print("ERROR: Unable to communicate with master!", file=sys.stderr)
        return 0  # ROS's rosgraph returns normally here
    graph = Graph()
    stop = stop or threading.Event()
    try:
        while not stop.is_set():
            graph.update()
            out.write(format_graph(graph))
            out.flush()
            if once:
                break
            stop.wait(1.0)
    except KeyboardInterrupt:
        pass
    return 0


def rosgraph_main() -> None:
    """rosgraph's entry point."""
    sys.exit(main(sys.argv[1:]))
