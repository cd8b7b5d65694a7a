"""``rostest [options] [package] FILE.test [arg:=value...]``: run a launch file's tests.

The file is found as roslaunch finds launch files (a path, or a name in a package); the run
(minros.launch.rostest) starts a master of its own unless ``--reuse-master``, the file's nodes,
then each ``<test>``. The console shows what ROS's rostest shows: the log file, where the
results go, one ``[Testcase: test<name>]`` line per test, rosunit's summary (``SUMMARY``,
``RESULT: SUCCESS|FAIL``, the counts); the launch's own messages go to the log file. The exit
status is 0 when every test passed, 1 when one did not run properly, 2 when checks failed.
"""

from __future__ import annotations

import argparse
import os
import sys
from pathlib import Path
from typing import List

USAGE = "usage: rostest [options] [package] <filename>"


def _parser(prog: str) -> argparse.ArgumentParser:
    p = argparse.ArgumentParser(prog=prog, usage=f"{prog} [options] [package] <filename>",
                                description="Run the <test> nodes of a launch file.")
    p.add_argument("positional", nargs="*", help="[package] file.test [arg:=value...]")
    p.add_argument("-t", "--text", action="store_true",
                   help="Run with stdout output instead of XML output")
    p.add_argument("--reuse-master", action="store_true",
                   help="Connect to an existing ROS master instead of spawning a new ROS master "
                        "on a custom port")
    p.add_argument("--clear", action="store_true", help="Clear all parameters when connecting "
                   "to an existing ROS master (only works with --reuse-master)")
    p.add_argument("--results-filename", default=None, help="results_filename")
    p.add_argument("--results-base-dir", default=None,
                   help="The base directory of the test results. The test result file is created "
                        "in a subfolder name PKG_DIR.")
    return p


def _package_of(path: Path) -> tuple:
    """(package name, folder) of the package holding ``path``, else ('', None)."""
    from minros import packages

    for folder in [path.parent, *path.parent.parents]:
        if (folder / "package.xml").is_file():
            return packages.manifest_name(folder) or folder.name, folder
    return "", None


def main(argv: List[str], prog: str | None = None) -> int:
    prog = prog or "rostest"
    options = _parser(prog).parse_args(argv)
    from minros.cli.launch import resolve_launch_arguments
    from minros.launch.config import LaunchError
    from minros.launch.rostest import run_rostest, summary_file
    from minros.tools.testing import summary_text

    try:
        files, args = resolve_launch_arguments(options.positional)
    except LaunchError as exc:
        print(f"{prog}: error: {exc}", file=sys.stderr)
        return 1
    if len(files) != 1:
        print(USAGE, file=sys.stderr)
        print(f"{prog}: error: You must specify a test file", file=sys.stderr)
        return 2
    test_file = Path(files[0])
    package, pkg_dir = _package_of(test_file.resolve())
    package = package or "rostest"
    env = dict(os.environ)
    if options.results_base_dir:
        env["ROS_TEST_RESULTS_DIR"] = options.results_base_dir
    if options.clear and options.reuse_master:
        from minros.tools.master import Master, MasterException

        try:
            Master("/rostest").deleteParam("/")
        except (MasterException, OSError):
            pass
    # As ROS's rostest: what the launch does goes to rostest's log file, not the console, which
    # shows the run's own test cases and rosunit's summary; errors go to stderr as well.
    log = _Log(env)
    print(f"... logging to {log.path}", flush=True)

    def loaded() -> None:
        if not options.text:
            results = summary_file(str(test_file), package, pkg_dir, options.results_filename, env)
            print(f"[ROSUNIT] Outputting test results to {results}", flush=True)

    try:
        outcome = run_rostest(str(test_file), package, pkg_dir, args,
                              reuse_master=options.reuse_master, text=options.text, env=env,
                              results_filename=options.results_filename, out=log.write,
                              err=log.error, loaded=loaded)
    except LaunchError as exc:
        print(f"{prog}: error: {exc}", file=sys.stderr)
        return 1
    except KeyboardInterrupt:
        return 130
    finally:
        log.close()
    for case in outcome.cases if not options.text else ():  # rosunit's XML runner's lines
        if case.passed:
            print(f"[Testcase: {case.name}] ... ok")
        else:
            print(f"[Testcase: {case.name}] ... FAILURE!\nFAILURE: {case.failure}\n" + "-" * 80)
    print("")
    if options.text:
        print("WARNING: overall test result is not accurate when --text is enabled")
    else:
        print(summary_text(outcome.results, outcome.failed_to_run))
    print(f"rostest log file is in {log.path}")
    # rostest's statuses: 1 when a test did not run properly, 2 when its checks failed
    if outcome.failed_to_run or (options.text and not outcome.ok):
        return 1
    return 0 if outcome.ok else 2


class _Log:
    """rostest's log file, ``$ROS_LOG_DIR/rostest-<host>-<pid>.log``."""

    def __init__(self, env: dict) -> None:
        import socket

        from minros.rosenv import ros_log_dir

        folder = ros_log_dir(env)
        self.path = folder / f"rostest-{socket.gethostname()}-{os.getpid()}.log"
        try:
            folder.mkdir(parents=True, exist_ok=True)
            self._file = open(self.path, "a", encoding="utf-8")  # noqa: SIM115 - closed in main
        except OSError:
            self._file = None

    def write(self, text: str) -> None:
        if self._file is not None:
            try:
                self._file.write(text + "\n")
                self._file.flush()
            except (OSError, ValueError):
                pass

    def error(self, text: str) -> None:
        self.write(text)
        print(text, file=sys.stderr, flush=True)

    def close(self) -> None:
        if self._file is not None:
            self._file.close()


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
