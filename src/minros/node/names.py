"""A node's names: its caller id, namespace and remappings, and the addresses it advertises.

Until ``init_node`` names it, a node is ``<ns>/unnamed`` and names resolve against its
namespace (rospy's rules for topics made before init_node); afterwards against the node, with
the command-line remappings resolved once. The master URI (``__master:=``, ROS_MASTER_URI) is
read on every use until init_node fixes it.
"""

from __future__ import annotations

import os
import time
import warnings
from typing import Dict, List, Sequence

from minros import names, rosenv
from minros.exceptions import ROSInitException

__all__ = ["NodeNames"]


class NodeNames:
    """Names, remappings and addresses of one node (rospy.names, for one node)."""

    def __init__(self, argv: Sequence[str]) -> None:
        argv = list(argv)
        self.argv_mappings: Dict[str, str] = names.load_mappings(argv)
        self.namespace_argv = argv
        self.caller_id = names.get_ros_namespace(argv=argv) + "unnamed"
        self.init_argv: List[str] | None = None
        #: True once init_node named the node
        self.named = False
        self._resolved_mappings: Dict[str, str] = {}
        self._master_uri: str | None = None

    def name_node(self, name: str, argv: List[str], argv_given: bool, anonymous: bool) -> None:
        """init_node's naming step: ``name`` (or ``__name:=``) in the namespace of ``argv``,
        anonymous if asked, remappings resolved, the master URI fixed."""
        if argv_given:  # as rospy: the names from today's argv, the mappings from import
            self.argv_mappings = names.load_mappings(argv)
        self.namespace_argv = argv
        self.init_argv = argv
        self._master_uri = rosenv.get_master_uri(remapped=self.argv_mappings.get("__master"))
        if "__name" in self.argv_mappings:
            name = self.argv_mappings["__name"]
            anonymous = False
        if anonymous:
            name = f"{name}_{os.getpid()}_{int(time.time() * 1000)}"
        if not names.is_legal_base_name(name):
            warnings.warn(f"'{name}' is not a legal ROS base name. This may cause problems with "
                          "other ROS tools.", stacklevel=4)
        self.caller_id = names.resolve_name(name, names.get_ros_namespace(argv=argv) + "unnamed")
        self._resolved_mappings = names.resolve_mappings(self._plain_mappings(), self.caller_id)
        self.named = True

    @property
    def resolved_mappings(self) -> Dict[str, str]:
        """The remappings resolved against the node's name (rospy.names' ``_resolved_mappings``,
        which rospy code reads and sets)."""
        return self._resolved_mappings

    @resolved_mappings.setter
    def resolved_mappings(self, value: Dict[str, str]) -> None:
        self._resolved_mappings = value

    @property
    def master_uri(self) -> str:
        """``__master:=``, else ROS_MASTER_URI, else the default (fixed once init_node ran)."""
        if self._master_uri is not None:
            return self._master_uri
        return rosenv.get_master_uri(remapped=self.argv_mappings.get("__master"))

    def get_namespace(self) -> str:
        """The node's namespace with trailing '/'."""
        return names.namespace(self.caller_id)

    def get_mappings(self) -> Dict[str, str]:
        """Command-line remappings (as given, unresolved; ``__name`` etc. included)."""
        return dict(self.argv_mappings)

    def resolve_name(self, name: str, caller_id: str | None = None) -> str:
        """Resolve ``name`` relative to the node (or ``caller_id``), applying remappings."""
        if caller_id is None:
            caller_id = self.caller_id
        if not name:
            return names.namespace(caller_id)
        resolved = names.resolve_name(name, caller_id)
        if caller_id == self.caller_id:
            mappings = self._resolved_mappings
        else:
            mappings = names.resolve_mappings(self._plain_mappings(), caller_id)
        return mappings.get(resolved, resolved)

    def resolve_name_without_node_name(self, name: str) -> str:
        """Resolve a topic/service name created before init_node (rospy semantics): relative to
        the namespace, with the command-line remappings; ``~name`` is an error then."""
        if names.is_private(name):
            raise ValueError("~name topics cannot be created before init_node() has been called")
        fake_caller_id = names.ns_join(names.get_ros_namespace(argv=self.namespace_argv), "node")
        resolved = names.resolve_name(name, fake_caller_id)
        for src, dst in self._plain_mappings().items():
            if names.resolve_name(src, fake_caller_id) == resolved:
                if names.is_private(dst):
                    raise ROSInitException(
                        f"due to the way this node is written, {name} cannot be remapped to a ~name. \n"
                        "The declaration of topics/services must be moved after the call to init_node()")
                return names.resolve_name(dst, fake_caller_id)
        return resolved

    def resolve_topic_name(self, name: str) -> str:
        """A topic or service name as the client library resolves it: against the node once
        init_node named it, against the namespace before."""
        if self.named:
            return self.resolve_name(name)
        return self.resolve_name_without_node_name(name)

    def remap_name(self, name: str, caller_id: str | None = None) -> str:
        """Remap ``name`` without otherwise resolving it (rospy.remap_name)."""
        if caller_id is None:
            caller_id = self.caller_id
        if name in self.argv_mappings:
            return names.resolve_name(self.argv_mappings[name], caller_id)
        return name

    def _plain_mappings(self) -> Dict[str, str]:
        """Remappings of graph names (not the ``__name``/``__ns``/... special keys)."""
        return {k: v for k, v in self.argv_mappings.items() if not k.startswith("__")}

    # -- addresses ---------------------------------------------------------------------------

    def host_name(self) -> str:
        """The host this node advertises in its URIs (``__hostname``/``__ip``, ROS_HOSTNAME,
        ROS_IP, else the machine's name)."""
        override = rosenv.get_address_override(argv=self.init_argv or self.namespace_argv)
        return override if override else rosenv.get_host_name()

    def bind_address(self) -> str:
        """Loopback when the advertised address is loopback, else every interface."""
        return rosenv.get_bind_address(
            rosenv.get_address_override(argv=self.init_argv or self.namespace_argv))
