"""nodelet manager | load pkg/Type manager [--no-bond] | unload name manager |
standalone pkg/Type: ROS's nodelet program for Python nodelets (minros.nodelet)."""

from __future__ import annotations

import signal
import sys
import threading
import uuid
from typing import List, Optional

import minros
from minros.bondpy import Bond
from minros.nodelet import Loader
from nodelet.srv import NodeletLoad, NodeletUnload

USAGE = """nodelet usage:
nodelet load pkg/Type manager [--no-bond]  - Launch a nodelet of type pkg/Type on manager manager
nodelet standalone pkg/Type   - Launch a nodelet of type pkg/Type in a standalone node
nodelet unload name manager   - Unload a nodelet by name from manager
nodelet manager               - Launch a nodelet manager node"""


def _usage(argv: List[str]) -> int:
    print("Your usage: \n" + " ".join(argv))
    print(USAGE)
    return 255


def _remappings(argv: List[str]) -> List[tuple]:
    """The command line's remappings (``from:=to``, not ``__name:=``-style special keys)."""
    pairs = []
    for arg in argv[1:]:
        if ":=" in arg and not arg.startswith("__") and not arg.startswith("_"):
            source, target = arg.split(":=", 1)
            pairs.append((source, target))
    return pairs


def _unload(name: str, manager: str) -> bool:
    minros.loginfo(f"Unloading nodelet {name} from manager {manager}")
    service = f"{manager}/unload_nodelet"
    try:
        minros.wait_for_service(service, 5.0)
        return bool(minros.ServiceProxy(service, NodeletUnload)(name=name).success)
    except (minros.ROSException, minros.ServiceException) as exc:
        minros.logfatal(f"Failed to unload nodelet '{name}` from manager `{manager}': {exc}")
        return False


def main(argv: Optional[List[str]] = None) -> int:
    argv = list(sys.argv if argv is None else argv)
    args = minros.myargv(argv)
    command = args[1] if len(args) > 1 else ""
    if command in ("-h", "--help"):
        print(USAGE)
        return 0
    if command == "manager":
        minros.init_node("manager", argv=argv)
        Loader()
        minros.spin()
        return 0
    if command == "standalone" and len(args) > 2:
        nodelet_type = args[2]
        minros.init_node(nodelet_type.replace("/", "_"), argv=argv)
        loader = Loader(provide_ros_api=False)
        # remappings are the node's own: resolved names already follow them
        if not loader.load(minros.get_name(), nodelet_type, {}, args[3:]):
            return 255
        minros.spin()
        loader.clear()
        return 0
    if command == "unload" and len(args) > 3:
        minros.init_node("nodelet_unloader", argv=argv, anonymous=True)
        return 0 if _unload(minros.resolve_name(args[2]), args[3]) else 255
    if command == "load" and len(args) > 3:
        nodelet_type, manager = args[2], args[3]
        rest = args[4:]
        bond_enabled = not (rest[:1] == ["--no-bond"])
        if not bond_enabled:
            rest = rest[1:]
        # As ROS's loader: Ctrl-C unloads the nodelet first, then shuts the node down.
        stop = threading.Event()
        minros.init_node(nodelet_type.replace("/", "_"), argv=argv, disable_signals=True)
        for sig in (signal.SIGINT, signal.SIGTERM):
            signal.signal(sig, lambda *_: stop.set())
        name = minros.get_name()
        manager = minros.resolve_name(manager)
        remaps = _remappings(argv)
        minros.loginfo(f"Loading nodelet {name} of type {nodelet_type} to manager {manager} "
                       "with the following remappings:")
        for source, target in remaps:
            minros.loginfo(f"{source} -> {target}")
        bond_id = f"{name}_{uuid.uuid4()}" if bond_enabled else ""
        service = f"{manager}/load_nodelet"
        minros.wait_for_service(service)
        try:
            done = minros.ServiceProxy(service, NodeletLoad)(
                name=name, type=nodelet_type, remap_source_args=[s for s, _ in remaps],
                remap_target_args=[t for _, t in remaps], my_argv=rest, bond_id=bond_id)
            ok = bool(done.success)
        except minros.ServiceException as exc:
            minros.logfatal(f"Failed to load nodelet '{name}` of type `{nodelet_type}` to "
                            f"manager `{manager}': {exc}")
            return 255
        if not ok:
            minros.logfatal(f"Failed to load nodelet '{name}` of type `{nodelet_type}` to "
                            f"manager `{manager}'")
            return 255
        bond = None
        if bond_enabled:
            bond = Bond(f"{manager}/bond", bond_id, on_broken=stop.set)
            bond.start()
        # until Ctrl-C, rosnode kill or the manager's death
        while not stop.wait(0.1) and not minros.is_shutdown():
            pass
        if bond is not None and bond.is_broken():
            minros.loginfo("Bond broken, exiting")
        else:
            _unload(name, manager)
        if bond is not None:
            bond.shutdown()
        minros.signal_shutdown("nodelet unloaded")
        return 0
    return _usage(argv)


if __name__ == "__main__":
    sys.exit(main())
