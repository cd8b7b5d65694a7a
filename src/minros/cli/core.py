"""``minros core`` (``roscore``): the master, the roscore parameters and the rosout node.

Like roscore it sets ``/run_id`` (a uuid1), ``/rosdistro`` and ``/rosversion`` (values end with a
newline, as ``rosversion`` prints them), starts rosout as its own process (respawned if it dies),
listens on ``-p PORT`` or else the port of ``ROS_MASTER_URI`` or 11311, and binds/advertises by
ROS_IP / ROS_HOSTNAME. Ctrl-C or SIGTERM stop everything cleanly. Imports are kept lazy so the
master answers quickly.
"""

from __future__ import annotations

import argparse
import os
import signal
import subprocess
import sys
import threading
import time
from pathlib import Path
from typing import Any, List
from urllib.parse import urlparse

from minros import logfiles
from minros.cli import rosversion
from minros.cli.rosversion import ROSDISTRO
from minros.rosenv import renew_latest_log_dir
from minros.signals import SignalWatch

DEFAULT_PORT = 11311
ROSCORE_PARAMS = ("/rosdistro", "/rosversion", "/run_id")
DISK_USAGE_WARNING = 1 << 30


def _version() -> str:
    try:
        from minros import __version__

        return __version__
    except ImportError:  # pragma: no cover - partial installs
        return "0.0.0"


def _port_from_env(env: Any) -> int | None:
    if not env.get("ROS_MASTER_URI"):
        return None
    from minros import rosenv

    # one that is not a URI is named with its fix (MasterURIError), not silently ignored
    return urlparse(rosenv.get_master_uri(env)).port


def _master_running(port: int) -> bool:
    """Whether a master already answers on ``port`` (loopback)."""
    import socket

    try:
        with socket.create_connection(("127.0.0.1", port), timeout=0.5):
            pass
    except OSError:
        return False
    from minros.wire.masterapi import MasterClient

    master = MasterClient(f"http://127.0.0.1:{port}/", "/roscore", timeout=1.0)
    try:
        master.get_pid()
        return True
    except Exception:  # noqa: BLE001 - whatever listens there is not a master
        return False
    finally:
        master.close()


class _Console:
    """stdout that never raises: a closed terminal or pipe must not stop the clean shutdown."""

    def __init__(self, stream: Any) -> None:
        self.stream = stream

    def write(self, text: str) -> None:
        if self.stream is None:
            return
        try:
            self.stream.write(text)
        except (OSError, ValueError):
            self.stream = None

    def flush(self) -> None:
        if self.stream is None:
            return
        try:
            self.stream.flush()
        except (OSError, ValueError):
            self.stream = None


class _Style:
    def __init__(self, tty: bool) -> None:
        self.bold = "\033[1m" if tty else ""
        self.red = "\033[31m" if tty else ""
        self.end = "\033[0m" if tty else ""


def _log_usage(directory: str) -> int:
    total = 0
    for root, _dirs, files in os.walk(directory):
        for name in files:
            try:
                total += os.lstat(os.path.join(root, name)).st_size
            except OSError:
                pass
    return total


class RosoutProcess:
    """The rosout node as a child process, respawned (with back-off) when it dies."""

    def __init__(self, uri: str, log_dir: str, env: dict) -> None:
        self.uri = uri
        self.log_dir = log_dir
        self.env = dict(env)
        self.env["ROS_MASTER_URI"] = uri
        self.env["MINROS_CORE_PID"] = str(os.getpid())  # rosout exits if we die
        self.env.setdefault("PYTHONUNBUFFERED", "1")
        self.popen: subprocess.Popen | None = None
        self.count = 0
        self.started_at = 0.0

    def start(self) -> int:
        self.count = 1 if not self.count else self.count
        log_path = os.path.join(self.log_dir, "rosout-1-stdout.log")
        try:
            out = open(log_path, "ab")  # noqa: SIM115 - handed to the child
        except OSError:
            out = subprocess.DEVNULL
        self.popen = subprocess.Popen(
            [sys.executable, "-m", "minros.nodes.rosout", "__name:=rosout",
             f"__log:={os.path.join(self.log_dir, 'rosout-1.log')}"],
            env=self.env, stdin=subprocess.DEVNULL, stdout=out, stderr=subprocess.STDOUT)
        if out is not subprocess.DEVNULL:
            out.close()
        self.started_at = time.monotonic()
        return self.popen.pid

    def rotate_log(self) -> None:
        """rosout's console log rotates as a node log does (its lines may quote peers)."""
        try:
            logfiles.rotate_copy_truncate(os.path.join(self.log_dir, "rosout-1-stdout.log"),
                                          logfiles.NODE_LOG_MAX_BYTES, logfiles.NODE_LOG_BACKUPS)
        except OSError:
            pass

    def died(self) -> bool:
        return self.popen is not None and self.popen.poll() is not None

    def stop(self) -> None:
        popen = self.popen
        if popen is None or popen.poll() is not None:
            return
        for sig, wait in ((signal.SIGINT, 3.0), (signal.SIGTERM, 2.0), (signal.SIGKILL, 2.0)):
            try:
                popen.send_signal(sig)
                popen.wait(wait)
                return
            except subprocess.TimeoutExpired:
                continue
            except ProcessLookupError:
                return


def main(argv: List[str], prog: str = "minros core") -> int:
    parser = argparse.ArgumentParser(
        prog=prog, description="Run a ROS master with the roscore parameters and rosout (roscore).")
    parser.add_argument("-p", "--port", type=int, default=None,
                        help="master port (default: ROS_MASTER_URI's port, else 11311)")
    parser.add_argument("--host", default=None,
                        help="host name or address to advertise and bind (default: ROS_HOSTNAME/ROS_IP)")
    parser.add_argument("-v", action="store_true", dest="verbose", help="print more")
    parser.add_argument("-w", "--numworkers", type=int, default=None,
                        help="threads making callbacks to nodes")
    parser.add_argument("-t", "--timeout", type=float, default=None,
                        help="timeout of one callback to a node, in seconds")
    parser.add_argument("--master-logger-level", default=None, help="accepted and ignored")
    parser.add_argument("--no-rosout", action="store_true", help="do not start the rosout node")
    args, rest = parser.parse_known_args(argv)
    for extra in rest:
        if not extra.startswith("__"):
            parser.error(f"unrecognized argument: {extra}")

    env = os.environ
    port = args.port or _port_from_env(env) or DEFAULT_PORT
    if not 0 < port < 65536:
        print(f"{prog}: invalid port {port}", file=sys.stderr)
        return 2
    style = _Style(sys.stdout.isatty())

    from minros import master as master_mod

    if _master_running(port):
        print(f"{style.red}{prog} cannot run as another roscore/master is already running on port "
              f"{port}.{style.end}", file=sys.stderr)
        return 1
    kwargs = {}
    if args.numworkers:
        kwargs["workers"] = max(1, args.numworkers)
    if args.timeout:
        kwargs["callback_timeout"] = args.timeout
    import uuid

    run_id = str(uuid.uuid1())
    version = _version()
    # roscore.xml sets /rosversion to `rosversion roslaunch`: the ros_comm release minros speaks
    ros_version = rosversion.version_of("roslaunch") or version
    try:
        core = master_mod.Master(port, hostname=args.host, **kwargs)
        # set before the server starts, so that no client ever sees a master without them
        core.handler.setParam("/roscore", "/rosdistro", ROSDISTRO + "\n")
        core.handler.setParam("/roscore", "/rosversion", ros_version + "\n")
        core.handler.setParam("/roscore", "/run_id", run_id)
        core.start()
    except OSError as exc:
        print(f"{prog}: cannot listen on port {port}: {exc.strerror or exc}", file=sys.stderr)
        return 1
    except ValueError as exc:
        print(f"{prog}: {exc}", file=sys.stderr)
        return 1

    stop = threading.Event()
    # set from a thread of its own, not in the handler (see minros.signals)
    SignalWatch(lambda _signum: stop.set(), "core-signals").install((signal.SIGINT, signal.SIGTERM))

    from minros.rosenv import ros_log_dir

    base_log = str(ros_log_dir(env))
    run_log = os.path.join(base_log, run_id)
    try:
        os.makedirs(run_log, exist_ok=True)
    except OSError as exc:
        print(f"{prog}: cannot create log directory {run_log}: {exc.strerror or exc}",
              file=sys.stderr)
        run_log = ""
    if run_log:
        renew_latest_log_dir(Path(run_log))
        master_mod.configure_log_file(os.path.join(run_log, "master.log"))
        master_mod._log.info("Master initialized: port[%s], uri[%s]", core.port, core.uri)
        for key in ROSCORE_PARAMS:
            master_mod._log.info("+PARAM [%s] by /roscore", key)
    out = _Console(sys.stdout)
    if run_log:
        out.write(f"... logging to {run_log}\n")
        out.write("Checking log directory for disk usage. This may take a while.\n"
                  "Press Ctrl-C to interrupt\n")
        usage = _log_usage(base_log)
        if usage > DISK_USAGE_WARNING:
            out.write(f"WARNING: disk usage in log directory [{base_log}] is over 1GB.\n"
                      "It's recommended that you use the 'rosclean' command.\n")
        else:
            out.write("Done checking log file disk usage. Usage is <1GB.\n")
    out.write(f"\nminros version {version}\n\n\nSUMMARY\n========\n\nPARAMETERS\n"
              f" * /rosdistro: {ROSDISTRO}\n * /rosversion: {ros_version}\n\nNODES\n\n"
              "auto-starting new master\n"
              f"{style.bold}process[master]: started with pid [{os.getpid()}]{style.end}\n"
              f"{style.bold}ROS_MASTER_URI={core.uri}{style.end}\n\n"
              f"{style.bold}setting /run_id to {run_id}{style.end}\n")
    out.flush()

    rosout: RosoutProcess | None = None
    if not args.no_rosout:
        rosout = RosoutProcess(core.uri, run_log or base_log, dict(env))
        try:
            pid = rosout.start()
            out.write(f"{style.bold}process[rosout-1]: started with pid [{pid}]{style.end}\n"
                      "started core service [/rosout]\n")
        except OSError as exc:
            out.write(f"rosout could not be started: {exc}\n")
            rosout = None
        out.flush()

    backoff = 1.0
    try:
        while not stop.is_set() and core.ok():
            stop.wait(0.5)
            if rosout is not None:
                rosout.rotate_log()
            if rosout is not None and rosout.died() and not stop.is_set() and core.ok():
                # respawn="true" in roscore.xml; back off if it keeps dying at start
                if time.monotonic() - rosout.started_at < 5.0:
                    stop.wait(backoff)
                    backoff = min(backoff * 2, 30.0)
                else:
                    backoff = 1.0
                if stop.is_set() or not core.ok():
                    break
                out.write("[rosout-1] restarting process\n")
                pid = rosout.start()
                out.write(f"{style.bold}process[rosout-1]: started with pid [{pid}]{style.end}\n")
                out.flush()
    finally:
        if rosout is not None:
            out.write("[rosout-1] killing on exit\n")
            rosout.stop()
        out.write("[master] killing on exit\n")
        core.stop()
        out.write("shutting down processing monitor...\n... shutting down processing monitor "
                  f"complete\n{style.bold}done{style.end}\n")
        out.flush()
    return 0
