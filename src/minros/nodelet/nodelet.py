"""The base class of Python nodelets."""

from __future__ import annotations

from typing import Dict, List

import minros
from minros import names

__all__ = ["Nodelet"]


class Nodelet:
    """Subclasses implement ``onInit()``; ``resolve_name`` gives a topic name as this
    nodelet sees it (relative to its namespace, private to its name, remapped as its
    loader asked), so two instances in one manager stay apart."""

    def __init__(self) -> None:
        self._name = ""
        self._remappings: Dict[str, str] = {}
        self._my_argv: List[str] = []
        self._inited = False

    def init(self, name: str, remappings: Dict[str, str], my_argv: List[str]) -> None:
        """Called by the loader (once); runs ``onInit``."""
        if self._inited:
            raise RuntimeError(f"nodelet {name} is already initialized")
        self._name = name
        self._remappings = dict(remappings)
        self._my_argv = list(my_argv)
        self._inited = True
        self.onInit()

    def onInit(self) -> None:
        raise NotImplementedError(f"{type(self).__name__} must implement onInit()")

    def onShutdown(self) -> None:
        """Called when the nodelet is unloaded (close publishers and timers here)."""

    def getName(self) -> str:
        return self._name

    def getMyArgv(self) -> List[str]:
        return list(self._my_argv)

    def getRemappings(self) -> Dict[str, str]:
        return dict(self._remappings)

    def getNamespace(self) -> str:
        return names.namespace(self._name)

    def getPrivateNamespace(self) -> str:
        return self._name

    def resolve_name(self, name: str, private: bool = False) -> str:
        """``name`` in this nodelet's namespace (``~name`` or ``private=True``: under its
        own name), with the loader's remappings applied."""
        if private and not name.startswith("~"):
            name = "~" + name
        if name.startswith("~"):
            resolved = names.ns_join(self._name, name[1:])
        elif name.startswith("/"):
            resolved = name
        else:
            resolved = names.ns_join(self.getNamespace(), name)
        resolved = names.canonicalize_name(resolved)
        return self._remappings.get(resolved, resolved)

    def loginfo(self, text: str) -> None:
        minros.loginfo(f"[{self._name}] {text}")
