"""``rostest [options] [package] FILE.test [arg:=value...]``: run a launch file's tests.

The file is found as roslaunch finds launch files (a path, or a name in a package); the run
(minros.launch.rostest) starts a master of its own unless ``--reuse-master``, the file's nodes,
then each ``<test>``; the exit status is 0 when every test passed, 1 otherwise.
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
    from minros.launch.rostest import run_rostest
    from minros.tools.testing import is_tty, summary_text

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
    env = dict(os.environ)
    if options.results_base_dir:
        env["ROS_TEST_RESULTS_DIR"] = options.results_base_dir
    if options.clear and options.reuse_master:
        from minros.tools.master import Master, MasterException

        try:
            Master("/rostest").deleteParam("/")
        except (MasterException, OSError):
            pass
    try:
        outcome = run_rostest(str(test_file), package or "rostest", pkg_dir, args,
                              reuse_master=options.reuse_master, text=options.text, env=env,
                              results_filename=options.results_filename,
                              err=lambda text: print(text, file=sys.stderr, flush=True))
    except LaunchError as exc:
        print(f"{prog}: error: {exc}", file=sys.stderr)
        return 1
    except KeyboardInterrupt:
        return 130
    print(summary_text(outcome.results, outcome.failed_to_run, color=is_tty()))
    if outcome.summary_file is not None:
        print(f"rostest log file is in {outcome.summary_file}")
    return 0 if outcome.ok else 1


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
