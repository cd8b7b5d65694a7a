"""``rosrun tf2_tools view_frames.py``: listen to tf for a while and draw the frame tree.

As tf2_tools' script: listens 5 s, asks its own ``~tf2_frames`` service for the frames,
writes ``frames.gv`` (Graphviz) and turns it into ``frames.pdf`` with ``dot``. When Graphviz
is not installed the tree is printed as text instead, with the command that would draw it.
``--png`` also writes ``frames.png``; ``--duration`` changes the 5 s.
"""

from __future__ import annotations

import argparse
import shutil
import subprocess
import sys
from typing import Any, Dict, List, Optional

from .tools import run_tool, tool_args

NAME = "view_frames"


def generate_dot(data: Dict[str, Dict[str, Any]], recorded_at: float) -> str:
    """The Graphviz text tf2_tools writes for ``all_frames_as_yaml`` data."""
    if not data:
        return 'digraph G { "No tf data received" }'
    parts = ["digraph G {\n"]
    roots: List[str] = []
    for child, info in data.items():
        parts.append(f'"{info["parent"]}" -> "{child}"[label=" Broadcaster: {info["broadcaster"]}\\n'
                     f'Average rate: {info["rate"]}\\nBuffer length: {info["buffer_length"]}\\n'
                     f'Most recent transform: {info["most_recent_transform"]}\\n'
                     f'Oldest transform: {info["oldest_transform"]}\\n"];\n')
        if info["parent"] not in data:
            roots.append(str(info["parent"]))
    parts.append("edge [style=invis];\n subgraph cluster_legend { style=bold; color=black; "
                 'label ="view_frames Result";\n')
    parts.append(f'"Recorded at time: {recorded_at}"[ shape=plaintext ] ;\n')
    # a tree with a loop has no root: the legend then hangs off nothing
    parts.append(f'}}->"{roots[-1]}";\n}}' if roots else "}\n}")
    return "".join(parts)


def text_tree(data: Dict[str, Dict[str, Any]]) -> str:
    """The frames as an indented tree, for a terminal without Graphviz."""
    children: Dict[str, List[str]] = {}
    for child, info in data.items():
        children.setdefault(str(info["parent"]), []).append(child)
    roots = sorted(p for p in children if p not in data) or sorted(children)[:1]
    lines: List[str] = []
    seen = set()

    def walk(frame: str, prefix: str, last: bool, top: bool) -> None:
        info = data.get(frame)
        label = frame
        if info is not None:
            static = info["most_recent_transform"] == 0.0
            label += (f"  ({info['broadcaster']}, static)" if static else
                      f"  ({info['broadcaster']}, {info['rate']} Hz, last at "
                      f"{info['most_recent_transform']})")
        lines.append(label if top else prefix + ("└── " if last else "├── ") + label)
        if frame in seen:
            return
        seen.add(frame)
        kids = sorted(children.get(frame, []))
        for i, kid in enumerate(kids):
            walk(kid, prefix if top else prefix + ("    " if last else "│   "), i == len(kids) - 1,
                 False)

    for root in roots:
        walk(root, "", True, True)
    return "\n".join(lines) + "\n"


def main(argv: Optional[List[str]] = None) -> int:
    import yaml

    import minros
    from tf2_msgs.srv import FrameGraph

    from .buffer import Buffer
    from .listener import TransformListener

    full_argv = list(sys.argv if argv is None else argv)
    parser = argparse.ArgumentParser(
        prog="view_frames.py", description="Listen to tf and draw the frame tree into frames.pdf.")
    parser.add_argument("--duration", type=float, default=5.0, metavar="SECONDS",
                        help="how long to listen (default 5)")
    parser.add_argument("--png", action="store_true", help="also write frames.png")
    args = parser.parse_args(tool_args(full_argv))
    minros.init_node("view_frames", argv=full_argv)
    minros.loginfo(f"Listening to tf data during {args.duration:g} seconds...")
    buffer = Buffer()
    TransformListener(buffer)
    minros.sleep(args.duration)
    minros.loginfo("Generating graph in frames.pdf file...")
    minros.wait_for_service("~tf2_frames", timeout=10.0)
    reply = minros.ServiceProxy("~tf2_frames", FrameGraph)()
    data = yaml.safe_load(reply.frame_yaml) or {}
    with open("frames.gv", "w") as f:
        f.write(generate_dot(data, minros.Time.now().to_sec()))
    dot = shutil.which("dot")
    if dot is None:
        sys.stdout.write(text_tree(data) if data else "No tf data received\n")
        sys.stderr.write("view_frames: Graphviz's dot is not installed, so no frames.pdf: the tree "
                         "is above and in frames.gv (install graphviz, then run "
                         "'dot -Tpdf frames.gv -o frames.pdf')\n")
        return 0
    formats = ["pdf"] + (["png"] if args.png else [])
    for fmt in formats:
        done = subprocess.run([dot, f"-T{fmt}", "frames.gv", "-o", f"frames.{fmt}"],
                              capture_output=True, text=True, timeout=60)
        if done.returncode != 0:
            sys.stderr.write(f"view_frames: dot failed to write frames.{fmt}: "
                             f"{done.stderr.strip()}\n")
            return 1
    return 0


if __name__ == "__main__":
    sys.exit(run_tool(NAME, main))
