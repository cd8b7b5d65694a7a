"""``minros learn``: exercises on the ROS 1 wire that check themselves.

    minros learn --list                          the exercises, numbered
    minros learn N [--dir D] [--via V]           start exercise N and explain the task
    minros learn check N [ANSWER...]             check an answer against your trace
    minros learn task N                          print the task of a started exercise again
"""

from __future__ import annotations

import argparse
import signal
import sys
import threading
from pathlib import Path
from typing import List, Optional

USAGE = """usage: minros learn --list
       minros learn N [--dir DIR] [--via VARIANT] [--seed S]
       minros learn check N [ANSWER...] [--dir DIR] [--trace FILE]
       minros learn task N [--dir DIR]

Short exercises on the ROS 1 wire (at most 5 minutes each). 'minros learn N' starts what the
exercise needs (a master, small nodes, each traced into the exercise's folder) and explains
the task; leave it running and work in another terminal. 'minros learn check N ANSWER' checks
your answer against your own trace, with a hint when it is not right yet. Offline, no root."""


def main(argv: List[str], prog: Optional[str] = None) -> int:
    prog = prog or "minros learn"
    if not argv or argv[0] in ("--list", "-l", "list"):
        print(_listing())
        if not argv:
            print("\nstart one with: minros learn N   (minros learn --help for more)")
        return 0
    if argv[0] in ("-h", "--help"):
        print(USAGE + "\n\n" + _listing())
        return 0
    from minros.learn.session import LearnError

    try:
        if argv[0] == "check":
            return _check(argv[1:], f"{prog} check")
        if argv[0] == "task":
            return _task(argv[1:], f"{prog} task")
        return _start(argv, prog)
    except LearnError as exc:
        print(f"{prog}: {exc}", file=sys.stderr)
        return 1


def _listing() -> str:
    from minros import learn

    lines = ["exercises:"]
    for ex in learn.exercises():
        lines.append(f"  {ex.number:>2}  {ex.title:<52} {ex.minutes} min")
    return "\n".join(lines)


def _number(text: str, prog: str) -> int:
    from minros import learn
    from minros.learn.session import LearnError

    try:
        number = int(text)
        learn.exercise(number)
    except ValueError:
        raise LearnError(f"{text!r} is not an exercise number (minros learn --list)") from None
    except LookupError as exc:
        raise LearnError(str(exc)) from None
    return number


def _base(args: argparse.Namespace) -> Path:
    from minros.learn.session import default_base

    return Path(args.dir).expanduser() if args.dir else default_base()


def _dir_option(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("--dir", metavar="DIR",
                        help="where exercises keep their folders (default $MINROS_LEARN_DIR, "
                             "else $ROS_HOME/learn, i.e. ~/.ros/learn)")


# --------------------------------------------------------------------------- start


def _start(argv: List[str], prog: str) -> int:
    from minros import learn
    from minros.learn.session import Runner
    from minros.signals import SignalWatch

    parser = argparse.ArgumentParser(
        prog=prog, description="Start exercise N: what it needs runs (traced) until Ctrl-C; "
                               "the task says what to do in another terminal.")
    parser.add_argument("number", metavar="N", help="the exercise (minros learn --list)")
    _dir_option(parser)
    parser.add_argument("--via", default="", metavar="VARIANT",
                        help="how exercise 11's masters are joined: zenoh (a minros zenoh "
                             "bridge on each, on loopback; the default when the eclipse-zenoh "
                             "package is installed) or relay (a node on each, joined by a "
                             "pipe; the default otherwise)")
    parser.add_argument("--seed", type=int, help="fix the exercise's random choices")
    args = parser.parse_args(argv)
    number = _number(args.number, prog)
    ex = learn.exercise(number)
    runner = Runner(ex, _base(args), variant=args.via, seed=args.seed,
                    say=lambda text: print(text, flush=True))
    stop = threading.Event()
    watch = SignalWatch(lambda signum: stop.set(), "minros-learn-signals")
    previous = watch.install((signal.SIGINT, signal.SIGTERM))
    try:
        print(f"minros learn {number}: {ex.title} (about {ex.minutes} minutes)", flush=True)
        if not args.via:
            for variant, why in ex.unavailable().items():
                print(f"(not --via {variant} here: {why})", flush=True)
        facts = runner.start()
        print("", flush=True)
        print(ex.task_text(facts), flush=True)
        print("", flush=True)
        if not runner.procs:
            print(f"(nothing to keep running; the folder is {facts['dir']})", flush=True)
            return 0
        names = ", ".join(f"{name} (pid {proc.pid})" for name, proc in runner.procs.items())
        print(f"running: {names}; traces and logs in {facts['dir']}", flush=True)
        print("Leave this running while you work in another terminal; Ctrl-C here stops the "
              "exercise.", flush=True)
        runner.wait(stop)
    finally:
        runner.stop()
        for signum, handler in previous.items():
            signal.signal(signum, handler)
    print(f"minros learn {number}: stopped; your traces stay in {runner.folder}", flush=True)
    return 0


# --------------------------------------------------------------------------- check


def _check(argv: List[str], prog: str) -> int:
    from minros import learn
    from minros.learn.session import folder_for, load_attempt

    parser = argparse.ArgumentParser(
        prog=prog, description="Check your answer to exercise N against your own trace (the "
                               "me*.jsonl files of the exercise's folder) and what the exercise "
                               "traced; exit status 0 when right, 1 with a hint when not.")
    parser.add_argument("number", metavar="N")
    parser.add_argument("answer", nargs=argparse.REMAINDER, metavar="ANSWER",
                        help="your answer, as the task asks for it")
    _dir_option(parser)
    parser.add_argument("--trace", action="append", default=[], metavar="FILE",
                        help="another trace of yours to read (repeatable)")
    # --dir and --trace may come anywhere; the first other word is N, the rest the answer
    options, words, rest = [], [], list(argv)
    while rest:
        word = rest.pop(0)
        if word in ("-h", "--help"):
            parser.print_help()
            return 0
        if word in ("--dir", "--trace") and rest:
            options += [word, rest.pop(0)]
        elif word.startswith(("--dir=", "--trace=")):
            options.append(word)
        else:
            words.append(word)
    args = parser.parse_args(options + words[:1])
    answer = words[1:]
    number = _number(args.number, prog)
    ex = learn.exercise(number)
    folder = folder_for(_base(args), ex)
    attempt = load_attempt(folder, answer, [Path(p) for p in args.trace])
    if not attempt.facts:
        print(f"{prog}: start the exercise first: minros learn {number}", file=sys.stderr)
        return 1
    result = learn.check(number, attempt.answer, attempt.traces, attempt.facts)
    print(result.text if result.ok else f"not yet: {result.text}")
    for line in result.details:
        print(line)
    if not result.ok and result.hint:
        print(f"hint: {result.hint}")
    return 0 if result.ok else 1


def _task(argv: List[str], prog: str) -> int:
    from minros import learn
    from minros.learn.session import folder_for, read_state

    parser = argparse.ArgumentParser(prog=prog, description="Print the task of exercise N as "
                                                            "its last start set it.")
    parser.add_argument("number", metavar="N")
    _dir_option(parser)
    args = parser.parse_args(argv)
    number = _number(args.number, prog)
    ex = learn.exercise(number)
    facts = read_state(folder_for(_base(args), ex))
    print(ex.task_text(facts))
    return 0
