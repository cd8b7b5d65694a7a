"""``minros trace``: watch the ROS wire. Record a trace, show it, turn it into a pcap.

    minros trace [-o FILE] [--messages] [--shm] -- COMMAND [ARGS...]   run COMMAND traced
    minros trace show [--follow] [--topic T] [--service S] FILE...
    minros trace pcap FILE... -o OUT.pcap
    minros trace dissector [-o minros.lua] [--type TYPE] [FILE...]

The first form runs COMMAND with ``MINROS_TRACE=FILE`` in its environment, so it and every
minros process it starts (a launch file's nodes, a core's rosout) append their events to FILE
(see :mod:`minros.wire.trace` for what is recorded, ``docs/internals.md`` for the format).
A traced process keeps to TCPROS, so that two minros nodes show the wire the course teaches
(they would take shared memory otherwise); ``--shm`` lets them (``MINROS_TRACE_SHM=1``).
"""

from __future__ import annotations

import argparse
import os
import shlex
import sys
import time
from typing import Any, List, Optional

USAGE = """usage: minros trace [-o FILE] [--messages] [--frames N] [--bytes N] [--shm] [--] COMMAND [ARGS...]
       minros trace show [--follow] [--topic T] [--service S] [--node N] [--frames N|all] [--all] FILE...
       minros trace pcap FILE... [-o OUT.pcap]
       minros trace dissector [-o minros.lua] [--type TYPE]... [FILE...]

Record what minros processes say on the ROS wire (XML-RPC calls, TCPROS connection headers,
message frames), then read it as the numbered sequence courses teach, or open it in Wireshark
(with the Lua dissector 'dissector' writes, message bodies are decoded by type).
Run 'minros trace show --help', 'minros trace pcap --help' or 'minros trace dissector --help'
for their options."""


def main(argv: List[str], prog: Optional[str] = None) -> int:
    prog = prog or "minros trace"
    if argv and argv[0] == "show":
        return _show(argv[1:], f"{prog} show")
    if argv and argv[0] == "pcap":
        return _pcap(argv[1:], f"{prog} pcap")
    if argv and argv[0] == "dissector":
        return _dissector(argv[1:], f"{prog} dissector")
    return _record(argv, prog)


# --------------------------------------------------------------------------- recording


def _record_parser(prog: str) -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(
        prog=prog, usage=USAGE.split("\n")[0][len("usage: "):],
        description="Run COMMAND with every minros process it starts writing a wire trace to "
                    "FILE (also: set MINROS_TRACE=FILE yourself). Then: minros trace show FILE.",
        epilog="Subcommands: 'minros trace show FILE...' prints the sequence per topic and "
               "service; 'minros trace pcap FILE -o out.pcap' writes a capture file.")
    parser.add_argument("-o", "--output", metavar="FILE",
                        help="the trace file, overwritten (default: trace-DATE-TIME.jsonl)")
    parser.add_argument("--messages", action="store_true",
                        help="decode every traced frame into its message (MINROS_TRACE_MESSAGES=1)")
    parser.add_argument("--frames", metavar="N",
                        help="frames kept per connection and direction (default 1000; 'all')")
    parser.add_argument("--bytes", metavar="N", type=int,
                        help="bytes of each frame kept (default 64)")
    parser.add_argument("--shm", action="store_true",
                        help="let minros nodes of this host use shared memory (MINROSSHM) "
                             "between them; without it a traced process keeps to TCPROS, the "
                             "wire courses teach")
    parser.add_argument("command", nargs=argparse.REMAINDER, help="the program to run, traced")
    return parser


def _record(argv: List[str], prog: str) -> int:
    from minros.transport import shm
    from minros.wire import trace

    if not argv:
        print(USAGE, file=sys.stderr)
        return 2
    if argv[0] in ("-h", "--help"):
        print(USAGE + "\n\n" + _record_parser(prog).format_help().split("\n", 2)[2].rstrip())
        return 0
    args = _record_parser(prog).parse_args(argv)
    command = args.command[1:] if args.command[:1] == ["--"] else args.command
    if not command:
        print(f"{prog}: error: name the command to trace: {prog} -o FILE -- COMMAND [ARGS...]",
              file=sys.stderr)
        return 2
    if args.frames is not None and args.frames != "all" and not args.frames.isdigit():
        print(f"{prog}: error: --frames takes a number or 'all', not {args.frames!r}",
              file=sys.stderr)
        return 2
    path = os.path.abspath(args.output or time.strftime("trace-%Y-%m-%d-%H-%M-%S.jsonl"))
    env = dict(os.environ)
    traced = True
    try:
        with open(path, "w"):
            pass
    except OSError as exc:
        print(f"{prog}: cannot write the trace to {path}: {exc.strerror or exc}; running "
              f"{os.path.basename(command[0])} without a trace (-o names a file you may write)",
              file=sys.stderr)
        env.pop(trace.ENV_FILE, None)
        traced = False
    if traced:
        env[trace.ENV_FILE] = path
        if args.messages:
            env[trace.ENV_MESSAGES] = "1"
        if args.frames is not None:
            env[trace.ENV_FRAMES] = args.frames
        if args.bytes is not None:
            env[trace.ENV_BYTES] = str(max(0, args.bytes))
        if args.shm:
            env[shm.TRACE_ENV] = "1"
        else:
            env.pop(shm.TRACE_ENV, None)
        print(f"{prog}: tracing into {path}; read it with: minros trace show {path}",
              file=sys.stderr)
    return _exec(command, env, prog)


def _exec(command: List[str], env: dict, prog: str) -> int:
    """Become ``command`` (as ``env`` does): its signals, terminal and exit status are its own,
    so Ctrl-C, ``kill`` and job control behave exactly as without the trace."""
    sys.stdout.flush()
    sys.stderr.flush()
    try:
        os.execvpe(command[0], command, env)
    except OSError as exc:
        print(f"{prog}: cannot run {command[0]}: {exc.strerror or exc}", file=sys.stderr)
        return 127
    return 0  # not reached


# --------------------------------------------------------------------------- show


def _frames_arg(text: str) -> int:
    if text == "all":
        return -1
    if not text.isdigit():
        raise argparse.ArgumentTypeError(f"a number or 'all', not {text!r}")
    return int(text)


def _load(paths: List[str], prog: str) -> list | None:
    """The trace files, or None after one line naming the first that cannot be read."""
    from minros.tools.trace import merge

    files = []
    for path in paths:
        try:
            files.append(merge.load(path))
        except merge.TraceError as exc:
            print(f"{prog}: {exc}", file=sys.stderr)
            return None
    return files


def _report_stops(files: list, prog: str) -> None:
    """One line per file whose trace ended early (cut mid-line, a bad record)."""
    for trace_file in files:
        if trace_file.stop:
            print(f"{prog}: {trace_file.stop}", file=sys.stderr)


def _show(argv: List[str], prog: str) -> int:
    from minros.tools.trace import merge, show

    parser = argparse.ArgumentParser(
        prog=prog, description="Print the wire sequence of a run per topic and per service, "
                               "numbered as courses number it, merging the traces of several "
                               "processes.")
    parser.add_argument("files", nargs="+", metavar="FILE", help="trace files (JSON lines)")
    parser.add_argument("-f", "--follow", action="store_true",
                        help="keep reading the files and print what arrives (Ctrl-C ends)")
    parser.add_argument("--topic", action="append", default=[], metavar="TOPIC",
                        help="only this topic (repeatable)")
    parser.add_argument("--service", action="append", default=[], metavar="SERVICE",
                        help="only this service (repeatable)")
    parser.add_argument("--node", action="append", default=[], metavar="NODE",
                        help="only what this node sends or receives (repeatable)")
    parser.add_argument("--frames", type=_frames_arg, default=3, metavar="N",
                        help="frames shown per connection and direction (default 3; 'all')")
    parser.add_argument("--all", action="store_true", dest="show_all",
                        help="also /rosout, the logger services and the master probes")
    args = parser.parse_args(argv)
    flt = show.Filter(args.topic, args.service, args.show_all, args.frames, args.node)
    if args.follow:
        return _follow(args.files, flt)
    files = _load(args.files, prog)
    if files is None:
        return 1
    for line in show.render(merge.split_runs(files), flt):
        print(line)
    _report_stops(files, prog)
    return 0


def _follow(paths: List[str], flt: Any) -> int:
    from minros.tools.trace import merge, show

    follower = merge.Follower(paths)
    view = show.LiveView(flt)
    warned: set = set()
    try:
        while True:
            for line in view.feed(follower.poll()):
                print(line, flush=True)
            for path, text in follower.bad.items():
                if path not in warned:
                    warned.add(path)
                    print(f"minros trace show: {text}", file=sys.stderr)
            time.sleep(0.2)
    except KeyboardInterrupt:
        return 0


# --------------------------------------------------------------------------- pcap


def _pcap(argv: List[str], prog: str) -> int:
    from minros.tools.trace import merge, pcap

    parser = argparse.ArgumentParser(
        prog=prog, description="Write a libpcap capture of the traced TCP connections (no root "
                               "needed): XML-RPC shows as HTTP, TCPROS decodes with Wireshark's "
                               "TCPROS dissector once its ports are set to it (Decode As; the "
                               "tshark command is printed after writing).")
    parser.add_argument("files", nargs="+", metavar="FILE", help="trace files (JSON lines)")
    parser.add_argument("-o", "--output", default="trace.pcap", metavar="OUT",
                        help="the capture file to write (default trace.pcap)")
    args = parser.parse_args(argv)
    files = _load(args.files, prog)
    if files is None:
        return 1
    items: list = []
    for run in merge.split_runs(files):
        items.extend(merge.merge(run)[0])
    packets, connections, ports = pcap.build(items)
    try:
        with open(args.output, "wb") as out:
            pcap.write(out, packets)
    except OSError as exc:
        print(f"{prog}: cannot write {args.output}: {exc.strerror or exc}", file=sys.stderr)
        return 1
    _report_stops(files, prog)
    print(f"wrote {len(packets)} packets of {connections} TCP connections to {args.output}")
    if ports:
        print(f"TCPROS servers listen on port{'s' if len(ports) > 1 else ''} "
              f"{', '.join(map(str, ports))}; decode every TCPROS connection with:")
        print("  " + " ".join(shlex.quote(arg) for arg in pcap.tshark_command(args.output, ports)))
        print("  (Wireshark: Analyze > Decode As..., TCP port, TCPROS; the tcpros_tcp heuristic "
              "alone finds only messages that start with a Header)")
        print("  or decode the message bodies by type: minros trace dissector -o minros.lua "
              f"{' '.join(map(shlex.quote, args.files))}; "
              f"tshark -X lua_script:minros.lua -r {shlex.quote(args.output)} -V")
    return 0


# --------------------------------------------------------------------------- dissector


def _dissector(argv: List[str], prog: str) -> int:
    from minros.tools.trace import dissector

    parser = argparse.ArgumentParser(
        prog=prog, description="Write a Lua dissector for Wireshark and tshark that finds TCPROS "
                               "connections by themselves and decodes message bodies by type, "
                               "from the message_definition of the connection headers in the "
                               "same capture (nested types, arrays, strings, time). Service "
                               "headers carry no definition: the service types named with "
                               "--type or found in the trace files given are written into it.",
        epilog="Then: tshark -X lua_script:minros.lua -r run.pcap -V (or copy minros.lua into "
               "Wireshark's personal Lua plugins folder, Help > About > Folders).")
    parser.add_argument("files", nargs="*", metavar="FILE",
                        help="trace files whose service types the dissector should know")
    parser.add_argument("-o", "--output", default="minros.lua", metavar="OUT",
                        help="the Lua file to write (default minros.lua; '-' for stdout)")
    parser.add_argument("--type", action="append", default=[], metavar="TYPE", dest="types",
                        help="a message or service type to embed (repeatable), e.g. "
                             "rospy_tutorials/AddTwoInts")
    args = parser.parse_args(argv)
    files = _load(args.files, prog) if args.files else []
    if files is None:
        return 1
    try:
        known = dissector.known_types(args.types)
    except dissector.UnknownType as exc:
        print(f"{prog}: {exc}; check the name with 'rosmsg show' or 'rossrv show'",
              file=sys.stderr)
        return 1
    found = dissector.types_in_events(ev for trace_file in files for ev in trace_file.events)
    extra = dissector.known_types([name for name in found if name not in known.services],
                                  quiet=True)
    known.services.update(extra.services)
    missing = [name for name in found if name not in known.services]
    try:
        from importlib.metadata import version

        minros_version = version("minros")
    except Exception:  # noqa: BLE001 - a source checkout without metadata
        minros_version = ""
    text = dissector.lua_source(known, minros_version)
    if args.output == "-":
        sys.stdout.write(text)
    else:
        try:
            with open(args.output, "w", encoding="utf-8") as out:
                out.write(text)
        except OSError as exc:
            print(f"{prog}: cannot write {args.output}: {exc.strerror or exc}", file=sys.stderr)
            return 1
    _report_stops(files, prog)
    names = sorted(known.services) + sorted(known.messages)
    where = sys.stderr if args.output == "-" else sys.stdout
    if args.output != "-":
        print(f"wrote {args.output}: TCPROS with message bodies decoded from the capture's "
              "connection headers" + (f", and the types {', '.join(names)}" if names else ""),
              file=where)
        print(f"  tshark -X lua_script:{shlex.quote(args.output)} -r run.pcap -V", file=where)
    if missing:
        print(f"{prog}: the service types {', '.join(missing)} are not known here: their "
              "bodies will show as bytes (ROS_PACKAGE_PATH names the packages that define them)",
              file=sys.stderr)
    return 0
