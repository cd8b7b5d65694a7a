"""``minros graph`` / ``rqt_graph``: the ROS computation graph as DOT, SVG or PNG.

The graph comes from the master's system state. As rqt_graph does by default, debug nodes
and topics (/rosout, /rosout_agg, /clock, /statistics, rqt, rviz, ...) are hidden, and the
default view shows nodes connected by edges labelled with topic names (``--topics`` draws
topics as boxes between nodes). Layout uses Graphviz's ``dot`` when installed, otherwise a
small built-in layered layout drawn with cv2/numpy (PNG) or hand-written SVG.
"""

from __future__ import annotations

import os
import shutil
import subprocess
import sys
from typing import Dict, List, Tuple
from xml.sax.saxutils import escape

from minros.tools.common import ToolError, parser, run_tool
from minros.tools.master import Master, is_quiet


class Graph:
    """Nodes, topics and edges; ``edges`` are (source, target, label)."""

    def __init__(self) -> None:
        self.nodes: List[str] = []           # ROS node names
        self.topics: List[str] = []          # topic names (drawn only in the topics view)
        self.edges: List[Tuple[str, str, str]] = []

    def vertices(self) -> List[str]:
        return self.nodes + self.topics


def build_graph(state: tuple, show_debug: bool = False, topics_view: bool = False,
                hide_dead_sinks: bool = True, hide_leaf_topics: bool = True) -> Graph:
    pubs, subs, _srvs = state
    publishers: Dict[str, List[str]] = {t: list(n) for t, n in pubs}
    subscribers: Dict[str, List[str]] = {t: list(n) for t, n in subs}
    keep = (lambda name: True) if show_debug else (lambda name: not is_quiet(name))
    graph = Graph()
    node_set = set()
    for table in (publishers, subscribers):
        for topic, nodes in table.items():
            if not keep(topic):
                continue
            node_set.update(n for n in nodes if keep(n))
    for topic in sorted(set(publishers) | set(subscribers)):
        if not keep(topic):
            continue
        pub_nodes = [n for n in publishers.get(topic, []) if keep(n)]
        sub_nodes = [n for n in subscribers.get(topic, []) if keep(n)]
        if topics_view:
            if hide_dead_sinks and not pub_nodes:
                continue  # nobody publishes: a dead sink
            if hide_leaf_topics and not sub_nodes:
                continue  # nobody listens: a leaf topic
            graph.topics.append(topic)
            graph.edges.extend((n, topic, "") for n in pub_nodes)
            graph.edges.extend((topic, n, "") for n in sub_nodes)
        else:
            graph.edges.extend((p, s, topic) for p in pub_nodes for s in sub_nodes)
    graph.nodes = sorted(node_set)
    return graph


# ---------------------------------------------------------------------------------------------
# DOT

def _dot_id(name: str, kind: str) -> str:
    return ("n_" if kind == "node" else "t_") + name.replace("/", "_")


def to_dot(graph: Graph) -> str:
    lines = ["digraph graphname {",
             '  graph [bgcolor="#ffffff00", rankdir=LR, rank=same, ranksep="0.2", compound=True];',
             '  node [label="\\N"];']
    for node in graph.nodes:
        lines.append(f'  "{_dot_id(node, "node")}" [label="{node}", shape=ellipse, URL="{node}"];')
    for topic in graph.topics:
        lines.append(f'  "{_dot_id(topic, "topic")}" [label="{topic}", shape=box, URL="topic:{topic}"];')
    kinds = {n: "node" for n in graph.nodes}
    kinds.update({t: "topic" for t in graph.topics})
    for src, dst, label in graph.edges:
        attrs = f' [label="{label}"]' if label else ""
        lines.append(f'  "{_dot_id(src, kinds[src])}" -> "{_dot_id(dst, kinds[dst])}"{attrs};')
    lines.append("}")
    return "\n".join(lines) + "\n"


# ---------------------------------------------------------------------------------------------
# built-in layered layout

CHAR_W = 7.5
BOX_H = 36.0
GAP_X = 90.0
GAP_Y = 30.0
MARGIN = 20.0


def layout(graph: Graph) -> Tuple[Dict[str, Tuple[float, float, float, float]], float, float]:
    """Positions (cx, cy, w, h) per vertex by longest-path ranks and barycenter ordering."""
    vertices = graph.vertices()
    succ: Dict[str, List[str]] = {v: [] for v in vertices}
    pred: Dict[str, List[str]] = {v: [] for v in vertices}
    for src, dst, _ in graph.edges:
        if src != dst and dst not in succ[src]:
            succ[src].append(dst)
            pred[dst].append(src)
    # break cycles: keep only edges that go forward in a DFS order
    order: Dict[str, int] = {}
    visiting = set()

    def dfs(v: str) -> None:
        visiting.add(v)
        for w in succ[v]:
            if w not in order and w not in visiting:
                dfs(w)
        visiting.discard(v)
        order[v] = len(order)

    for v in vertices:
        if v not in order:
            dfs(v)
    forward = [(s, d) for s in vertices for d in succ[s] if order[s] > order[d]]
    rank: Dict[str, int] = {v: 0 for v in vertices}
    for v in sorted(vertices, key=lambda x: -order[x]):
        for s, d in forward:
            if s == v:
                rank[d] = max(rank[d], rank[v] + 1)
    layers: Dict[int, List[str]] = {}
    for v in vertices:
        layers.setdefault(rank[v], []).append(v)
    for _ in range(4):  # barycenter sweeps to reduce crossings
        for r in sorted(layers):
            if r == 0:
                continue
            prev = {v: i for i, v in enumerate(layers[r - 1])}

            def bary(v: str, prev: Dict[str, int] = prev) -> float:
                ps = [prev[p] for p in pred[v] if p in prev]
                return sum(ps) / len(ps) if ps else float(len(prev))

            layers[r].sort(key=bary)
    sizes = {v: (max(60.0, CHAR_W * len(v) + 24.0), BOX_H) for v in vertices}
    positions: Dict[str, Tuple[float, float, float, float]] = {}
    x = MARGIN
    height = 0.0
    for r in sorted(layers):
        col_w = max(sizes[v][0] for v in layers[r])
        y = MARGIN
        for v in layers[r]:
            w, h = sizes[v]
            positions[v] = (x + col_w / 2, y + h / 2, w, h)
            y += h + GAP_Y
        height = max(height, y)
        x += col_w + GAP_X
    return positions, max(x - GAP_X + MARGIN, 2 * MARGIN), max(height - GAP_Y + MARGIN, 2 * MARGIN)


def _edge_points(pos: Dict, src: str, dst: str) -> Tuple[float, float, float, float]:
    x1, y1, w1, _ = pos[src]
    x2, y2, w2, _ = pos[dst]
    if x2 >= x1:
        return x1 + w1 / 2, y1, x2 - w2 / 2, y2
    return x1 - w1 / 2, y1, x2 + w2 / 2, y2


def to_svg(graph: Graph) -> str:
    pos, width, height = layout(graph)
    out = [f'<svg xmlns="http://www.w3.org/2000/svg" width="{width:.0f}" height="{height:.0f}" '
           f'viewBox="0 0 {width:.0f} {height:.0f}">',
           '<defs><marker id="arrow" markerWidth="10" markerHeight="8" refX="10" refY="4" '
           'orient="auto"><path d="M0,0 L10,4 L0,8 z" fill="#333"/></marker></defs>',
           f'<rect width="{width:.0f}" height="{height:.0f}" fill="white"/>']
    for src, dst, label in graph.edges:
        if src == dst:
            continue
        x1, y1, x2, y2 = _edge_points(pos, src, dst)
        out.append(f'<line x1="{x1:.1f}" y1="{y1:.1f}" x2="{x2:.1f}" y2="{y2:.1f}" stroke="#333" '
                   'marker-end="url(#arrow)"/>')
        if label:
            out.append(f'<text x="{(x1 + x2) / 2:.1f}" y="{(y1 + y2) / 2 - 4:.1f}" font-family="sans-serif" '
                       f'font-size="11" text-anchor="middle" fill="#444">{escape(label)}</text>')
    for v in graph.nodes:
        cx, cy, w, h = pos[v]
        out.append(f'<g class="node"><title>{escape(v)}</title><ellipse cx="{cx:.1f}" cy="{cy:.1f}" '
                   f'rx="{w / 2:.1f}" ry="{h / 2:.1f}" fill="white" stroke="black"/>'
                   f'<text x="{cx:.1f}" y="{cy + 4:.1f}" font-family="sans-serif" font-size="12" '
                   f'text-anchor="middle">{escape(v)}</text></g>')
    for t in graph.topics:
        cx, cy, w, h = pos[t]
        out.append(f'<g class="topic"><title>{escape(t)}</title><rect x="{cx - w / 2:.1f}" '
                   f'y="{cy - h / 2:.1f}" width="{w:.1f}" height="{h:.1f}" fill="white" stroke="black"/>'
                   f'<text x="{cx:.1f}" y="{cy + 4:.1f}" font-family="sans-serif" font-size="12" '
                   f'text-anchor="middle">{escape(t)}</text></g>')
    out.append("</svg>")
    return "\n".join(out) + "\n"


def to_png(graph: Graph) -> bytes:
    import cv2
    import numpy as np

    pos, width, height = layout(graph)
    img = np.full((int(height) + 1, int(width) + 1, 3), 255, dtype=np.uint8)
    font = cv2.FONT_HERSHEY_SIMPLEX
    scale = 0.4
    for src, dst, label in graph.edges:
        if src == dst:
            continue
        x1, y1, x2, y2 = _edge_points(pos, src, dst)
        cv2.arrowedLine(img, (int(x1), int(y1)), (int(x2), int(y2)), (51, 51, 51), 1, cv2.LINE_AA,
                        tipLength=min(0.3, 10.0 / max(1.0, ((x2 - x1) ** 2 + (y2 - y1) ** 2) ** 0.5)))
        if label:
            (tw, _th), _ = cv2.getTextSize(label, font, scale * 0.9, 1)
            cv2.putText(img, label, (int((x1 + x2) / 2 - tw / 2), int((y1 + y2) / 2 - 4)), font,
                        scale * 0.9, (68, 68, 68), 1, cv2.LINE_AA)
    for v in graph.vertices():
        cx, cy, w, h = pos[v]
        if v in graph.topics:
            cv2.rectangle(img, (int(cx - w / 2), int(cy - h / 2)), (int(cx + w / 2), int(cy + h / 2)),
                          (0, 0, 0), 1, cv2.LINE_AA)
        else:
            cv2.ellipse(img, (int(cx), int(cy)), (int(w / 2), int(h / 2)), 0, 0, 360, (0, 0, 0), 1, cv2.LINE_AA)
        (tw, th), _ = cv2.getTextSize(v, font, scale, 1)
        cv2.putText(img, v, (int(cx - tw / 2), int(cy + th / 2)), font, scale, (0, 0, 0), 1, cv2.LINE_AA)
    ok, data = cv2.imencode(".png", img)
    if not ok:
        raise ToolError("cannot encode the PNG image")
    return data.tobytes()


def render(graph: Graph, fmt: str, use_dot: bool | None = None) -> bytes:
    """The graph in ``fmt`` ('dot', 'svg', 'png'); Graphviz when available unless told not to."""
    if fmt == "dot":
        return to_dot(graph).encode()
    dot = shutil.which("dot") if use_dot is not False else None
    if dot:
        try:
            done = subprocess.run([dot, f"-T{fmt}"], input=to_dot(graph).encode(), capture_output=True,
                                  timeout=30, check=False)
            if done.returncode == 0 and done.stdout:
                return done.stdout
        except (OSError, subprocess.TimeoutExpired):
            pass
    return to_svg(graph).encode() if fmt == "svg" else to_png(graph)


def main(argv: List[str], prog: str = "rqt_graph") -> int:
    p = parser(prog, description="Draw the ROS node/topic graph (rqt_graph without the GUI).")
    p.add_argument("-o", "--output", metavar="FILE",
                   help="write to FILE (.dot/.gv, .svg or .png); default: DOT on stdout")
    p.add_argument("-f", "--format", choices=("dot", "svg", "png"), help="output format (default: from FILE's extension)")
    p.add_argument("--topics", action="store_true", help="draw topics as boxes (rqt_graph's 'Nodes/Topics (all)')")
    p.add_argument("--show-debug", action="store_true", help="do not hide debug nodes and topics (/rosout, ...)")
    p.add_argument("--show-dead-sinks", action="store_true", help="with --topics: show topics nobody publishes")
    p.add_argument("--show-leaf-topics", action="store_true", help="with --topics: show topics nobody subscribes")
    p.add_argument("--no-dot", action="store_true", help="use the built-in layout even if Graphviz is installed")
    args = p.parse_args([a for a in argv if ":=" not in a])

    def run() -> int:
        fmt = args.format
        if fmt is None and args.output:
            ext = os.path.splitext(args.output)[1].lower()
            fmt = {".dot": "dot", ".gv": "dot", ".svg": "svg", ".png": "png"}.get(ext)
            if fmt is None:
                raise ToolError(f"cannot tell the format of [{args.output}]: use .dot, .svg or .png, or --format")
        fmt = fmt or "dot"
        state = Master("/rqt_graph").system_state()
        graph = build_graph(state, args.show_debug, args.topics, not args.show_dead_sinks,
                            not args.show_leaf_topics)
        data = render(graph, fmt, use_dot=False if args.no_dot else None)
        if args.output and args.output != "-":
            try:
                with open(args.output, "wb") as f:
                    f.write(data)
            except OSError as exc:
                raise ToolError(f"cannot write [{args.output}]: {exc.strerror}") from None
        else:
            if fmt == "png" and sys.stdout.isatty():
                raise ToolError("refusing to write a PNG image to a terminal; use -o FILE")
            sys.stdout.buffer.write(data)
            sys.stdout.flush()
        return 0

    return run_tool(run)
