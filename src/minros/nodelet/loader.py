"""The nodelet Loader (nodelets of one process, by name) and LoaderROS (its services and
the bonds with the processes that asked for each nodelet)."""

from __future__ import annotations

import threading
from typing import Any, Dict, List, Optional

import minros
from minros.bondpy import Bond
from minros.nodelet.nodelet import Nodelet
from minros.nodelet.plugins import NodeletTypeError, find_class
from nodelet.srv import (
    NodeletList,
    NodeletListResponse,
    NodeletLoad,
    NodeletLoadResponse,
    NodeletUnload,
    NodeletUnloadResponse,
)

__all__ = ["Loader", "LoaderROS"]


class Loader:
    """Nodelets of this process, by name; with ``provide_ros_api`` the manager's services
    under the node's private namespace."""

    def __init__(self, provide_ros_api: bool = True) -> None:
        self.lock = threading.RLock()
        self.nodelets: Dict[str, Nodelet] = {}
        self.services = LoaderROS(self) if provide_ros_api else None

    def load(self, name: str, type: str, remappings: Dict[str, str],  # noqa: A002
             my_argv: List[str]) -> bool:
        with self.lock:
            if name in self.nodelets:
                minros.logerr(f"Cannot load nodelet {name} for one exists with that name already")
                return False
            try:
                cls = find_class(type)
            except NodeletTypeError as exc:
                minros.logerr(f"Failed to load nodelet [{name}] of type [{type}]: {exc}")
                return False
            try:
                instance = cls()
                instance.init(name, remappings, my_argv)
            except Exception as exc:  # noqa: BLE001 - a nodelet's own failure: refuse the load
                minros.logerr(f"Failed to initialize nodelet [{name}] of type [{type}]: "
                              f"{type_name(exc)}: {exc}")
                return False
            self.nodelets[name] = instance
            return True

    def unload(self, name: str) -> bool:
        with self.lock:
            instance = self.nodelets.pop(name, None)
        if instance is None:
            return False
        try:
            instance.onShutdown()
        except Exception as exc:  # noqa: BLE001 - unloaded all the same
            minros.logerr(f"nodelet {name} failed in onShutdown: {exc}")
        return True

    def clear(self) -> bool:
        for name in self.listLoadedNodelets():
            self.unload(name)
        return True

    def listLoadedNodelets(self) -> List[str]:
        with self.lock:
            return list(self.nodelets)


def type_name(exc: BaseException) -> str:
    return type(exc).__name__


class LoaderROS:
    """``~load_nodelet``, ``~unload_nodelet``, ``~list`` and the bonds on ``~bond``."""

    def __init__(self, parent: Loader) -> None:
        self.parent = parent
        self.bonds: Dict[str, Bond] = {}
        self.bond_lock = threading.Lock()
        self.bond_topic = minros.resolve_name("~bond")
        minros.Service("~load_nodelet", NodeletLoad, self.service_load)
        minros.Service("~unload_nodelet", NodeletUnload, self.service_unload)
        minros.Service("~list", NodeletList, self.service_list)

    def service_load(self, req: Any) -> Any:
        if len(req.remap_source_args) != len(req.remap_target_args):
            minros.logerr("Bad remapppings provided, target and source of different length")
            return NodeletLoadResponse(success=False)
        remappings = {minros.resolve_name(s): minros.resolve_name(t)
                      for s, t in zip(req.remap_source_args, req.remap_target_args)}
        success = self.parent.load(req.name, req.type, remappings, list(req.my_argv))
        if success and req.bond_id:
            bond = Bond(self.bond_topic, req.bond_id,
                        on_broken=lambda name=req.name: self._bond_broken(name))
            with self.bond_lock:
                self.bonds[req.name] = bond
            bond.start()
        return NodeletLoadResponse(success=success)

    def _bond_broken(self, name: str) -> None:
        minros.loginfo(f"the loader of nodelet {name} is gone (bond broken): unloading it")
        self.unload(name, break_bond=False)

    def unload(self, name: str, break_bond: bool = True) -> bool:
        success = self.parent.unload(name)
        if not success:
            minros.logerr(f"Failed to find nodelet with name '{name}' to unload.")
        with self.bond_lock:
            bond: Optional[Bond] = self.bonds.pop(name, None)
        if bond is not None:
            bond.set_broken_callback(lambda: None)  # we end it on purpose
            if break_bond:
                bond.shutdown()
            else:
                threading.Thread(target=bond.shutdown, daemon=True).start()
        return success

    def service_unload(self, req: Any) -> Any:
        return NodeletUnloadResponse(success=self.unload(req.name))

    def service_list(self, req: Any) -> Any:
        return NodeletListResponse(nodelets=self.parent.listLoadedNodelets())
