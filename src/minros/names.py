"""ROS graph resource names: canonical form, namespaces, resolution, remapping arguments.

Semantics follow ``rosgraph.names`` (and the few ``rospy.names``/``rospy.myargv`` helpers built on
it) so that names resolve identically in minros, rospy, roscpp and rosmaster:

* ``/a/b`` is global, ``~a`` private (relative to the node name), anything else relative to the
  namespace of the node (``namespace('/ns/node') == '/ns/'``);
* canonical form collapses ``//`` and drops a trailing ``/``;
* ``a:=b`` command-line arguments are remappings; ``_p:=v`` are private parameters;
  ``__name:=``, ``__ns:=`` ... are special keys kept as they are.
"""

from __future__ import annotations

import os
import re
import sys
from typing import Any, Dict, List, Mapping, Sequence

SEP = "/"
GLOBALNS = "/"
PRIV_NAME = "~"
REMAP = ":="
#: Type wildcard accepted by the master and by TCPROS (subscribers of any type, ``rostopic echo``).
ANYTYPE = "*"
TOPIC_ANYTYPE = ANYTYPE
SERVICE_ANYTYPE = ANYTYPE

#: Environment variable naming the node's namespace.
ROS_NAMESPACE = "ROS_NAMESPACE"

_NAME_LEGAL = re.compile(r"[\~\/A-Za-z][\w\/]*")
_BASE_NAME_LEGAL = re.compile(r"[A-Za-z]\w*")
_REMAP_LEGAL = re.compile(r"([\~\/A-Za-z]|_|__)[\w\/]*" + REMAP + ".*")


def is_global(name: str) -> bool:
    """True for ``/x`` (a name referenced from the root namespace)."""
    return bool(name) and name[0] == SEP


def is_private(name: str) -> bool:
    """True for ``~x`` (a name inside the node's own namespace)."""
    return bool(name) and name[0] == PRIV_NAME


def canonicalize_name(name: str) -> str:
    """Collapse repeated slashes and drop a trailing one: ``//a//b/`` -> ``/a/b``.

    ``''`` and ``'/'`` are returned unchanged.
    """
    if not name or name == SEP:
        return name
    parts = [p for p in name.split(SEP) if p]
    if name[0] == SEP:
        return SEP + SEP.join(parts)
    return SEP.join(parts)


def namespace(name: str) -> str:
    """Namespace of ``name`` with a trailing slash: ``/wg/node1`` -> ``/wg/``; ``''`` -> ``/``.

    A trailing slash on ``name`` is ignored (``/a/b/`` -> ``/a/``).
    """
    if name is None:
        raise ValueError("name")
    if not isinstance(name, str):
        raise TypeError("name")
    if not name:
        return SEP
    if name[-1] == SEP:
        name = name[:-1]
    return name[: name.rfind(SEP) + 1] or SEP


def ns_join(ns: str, name: str) -> str:
    """Join ``ns`` and ``name``; a global or private ``name`` is returned as it is."""
    if is_private(name) or is_global(name):
        return name
    if ns == PRIV_NAME:
        return PRIV_NAME + name
    if not ns:
        return name
    if ns[-1] == SEP:
        return ns + name
    return ns + SEP + name


def make_global_ns(name: str) -> str:
    """``foo`` -> ``/foo/`` (no resolution). Raises ``ValueError`` for ``~names``."""
    if is_private(name):
        raise ValueError(f"cannot turn [{name}] into a global name")
    if not is_global(name):
        name = SEP + name
    if name[-1] != SEP:
        name = name + SEP
    return name


def get_ros_namespace(env: Mapping[str, str] | None = None,
                      argv: Sequence[str] | None = None) -> str:
    """The program's namespace: ``__ns:=`` beats ``ROS_NAMESPACE``; always global with trailing ``/``."""
    if argv is None:
        argv = sys.argv
    for arg in argv:
        if arg.startswith("__ns:="):
            return make_global_ns(arg[len("__ns:="):])
    if env is None:
        env = os.environ
    return make_global_ns(env.get(ROS_NAMESPACE, GLOBALNS))


def make_caller_id(name: str, env: Mapping[str, str] | None = None,
                   argv: Sequence[str] | None = None) -> str:
    """Caller ID for a local node name in the current namespace, e.g. ``/ns/node/``."""
    return make_global_ns(ns_join(get_ros_namespace(env, argv), name))


def resolve_name(name: str, namespace_: str, remappings: Mapping[str, str] | None = None) -> str:
    """Resolve ``name`` to its global canonical form relative to the node name ``namespace_``.

    ``''`` resolves to the namespace of ``namespace_``; ``~x`` to ``namespace_/x``; ``x`` to
    ``namespace(namespace_) + x``. ``remappings`` (resolved name -> name) are applied last, to the
    resolved name.
    """
    if not name:
        return namespace(namespace_)
    name = canonicalize_name(name)
    if name[0] == SEP:
        resolved = name
    elif name[0] == PRIV_NAME:
        # Canonicalize the joined form so that '~' on an empty node name cannot make
        # the remainder accidentally relative or doubly slashed.
        resolved = canonicalize_name(namespace_ + SEP + name[1:])
    else:
        resolved = namespace(namespace_) + name
    if remappings and resolved in remappings:
        return remappings[resolved]
    return resolved


def script_resolve_name(script_name: str, name: str) -> str:
    """Resolve for command-line scripts: honours ``ROS_NAMESPACE``, no remapping."""
    if not name:
        return get_ros_namespace()
    if is_global(name):
        return name
    if is_private(name):
        return ns_join(make_caller_id(script_name), name[1:])
    return get_ros_namespace() + name


def scoped_name(caller_id: str, name: str) -> str:
    """``name`` relative to the namespace of the global ``caller_id`` (not validated)."""
    if not is_global(caller_id):
        from minros.exceptions import ROSException

        raise ROSException("caller_id must be global")
    return canonicalize_name(name)[len(namespace(caller_id)):]


def is_legal_name(name: str | None) -> bool:
    """Legal graph resource name: ``[~/A-Za-z][\\w/]*`` without ``//``; ``''`` is legal."""
    if name is None:
        return False
    if name == "":
        return True
    return _NAME_LEGAL.fullmatch(name) is not None and "//" not in name


def is_legal_base_name(name: str | None) -> bool:
    """Legal base name (no namespace): ``[A-Za-z]\\w*``."""
    if name is None:
        return False
    return _BASE_NAME_LEGAL.fullmatch(name) is not None


def is_legal_remap(arg: str | None) -> bool:
    """Whether a command-line argument is a remapping (``from:=to``, ``_param:=v``, ``__name:=n``)."""
    if arg is None:
        return False
    return _REMAP_LEGAL.fullmatch(arg) is not None


def _split_remap(arg: str) -> List[str] | None:
    parts = [x.strip() for x in arg.split(REMAP)]
    if len(parts) != 2:
        return None
    return parts


def _is_private_param(src: str) -> bool:
    """``_p`` (a private parameter assignment), as opposed to a name or a ``__special`` key."""
    return len(src) > 1 and src[0] == "_" and src[1] != "_"


def load_mappings(argv: Sequence[str]) -> Dict[str, str]:
    """Name remappings from command-line arguments (``a:=b`` and ``__key:=v``; not ``_param:=v``)."""
    mappings: Dict[str, str] = {}
    for arg in argv:
        if not is_legal_remap(arg):
            continue
        parts = _split_remap(arg)
        if parts is None:
            sys.stderr.write(f"ERROR: Invalid remapping argument '{arg}'\n")
            continue
        src, dst = parts
        if not src or not dst:
            continue
        if _is_private_param(src):
            continue  # a private parameter assignment, not a name
        mappings[src] = dst
    return mappings


def load_command_line_node_params(argv: Sequence[str]) -> Dict[str, Any]:
    """Private parameters ``_p:=value`` -> ``{'p': yaml.safe_load(value)}`` (rospy semantics).

    Raises ``ValueError`` for a value that is not valid YAML.
    """
    import yaml  # lazily: most callers never pass private parameters

    params: Dict[str, Any] = {}
    for arg in argv:
        if not is_legal_remap(arg):
            continue
        parts = _split_remap(arg)
        if parts is None:
            raise ValueError(f"invalid command-line parameter: {arg}")
        src, dst = parts
        if dst and _is_private_param(src):
            try:
                params[src[1:]] = yaml.safe_load(dst)
            except yaml.YAMLError as exc:
                raise ValueError(f"invalid command-line parameter {arg}: {exc}") from None
    return params


def resolve_mappings(mappings: Mapping[str, str], node_name: str) -> Dict[str, str]:
    """Resolve both sides of remappings against ``node_name``; ``__keys`` are kept as they are."""
    resolved: Dict[str, str] = {}
    for src, dst in mappings.items():
        if src.startswith("__"):
            resolved[src] = dst
        else:
            resolved[resolve_name(src, node_name)] = resolve_name(dst, node_name)
    return resolved


def strip_remapping_args(argv: Sequence[str]) -> List[str]:
    """``argv`` without remapping arguments (``rospy.myargv``)."""
    return [a for a in argv if not is_legal_remap(a)]


def anonymous_name(id: str) -> str:  # noqa: A002 - the ROS API's parameter name
    """``id_<hostname>_<pid>_<random>`` with ``.``, ``-`` and ``:`` replaced by ``_``."""
    import random
    import socket

    name = f"{id}_{socket.gethostname()}_{os.getpid()}_{random.randint(0, sys.maxsize)}"
    return name.replace(".", "_").replace("-", "_").replace(":", "_")


# ---------------------------------------------------------------------------------------------
# package resource names (``pkg/Type``: message, service and node types), as genmsg.names and
# roslib.names read them

PRN_SEPARATOR = "/"
_RESOURCE_NAME_LEGAL = re.compile(r"[A-Za-z][\w/]*")


def package_resource_name(name: str) -> tuple:
    """``'std_msgs/String'`` -> ``('std_msgs', 'String')``; ``'String'`` -> ``('', 'String')``.

    Raises ``ValueError`` for more than one separator.
    """
    if PRN_SEPARATOR in name:
        parts = tuple(name.split(PRN_SEPARATOR))
        if len(parts) != 2:
            raise ValueError(f"invalid name [{name}]")
        return parts
    return "", name


def resource_name(res_pkg_name: str, name: str, my_pkg: str | None = None) -> str:
    """``pkg/name``, or ``name`` alone when it is in ``my_pkg``."""
    if res_pkg_name != my_pkg:
        return res_pkg_name + PRN_SEPARATOR + name
    return name


def resource_name_base(name: str) -> str:
    """``'pkg/Type'`` -> ``'Type'``."""
    return name[name.rfind(PRN_SEPARATOR) + 1:]


def resource_name_package(name: str) -> str | None:
    """``'pkg/Type'`` -> ``'pkg'``; ``'Type'`` -> None."""
    if PRN_SEPARATOR not in name:
        return None
    return name[:name.find(PRN_SEPARATOR)]


def is_legal_resource_name(name: str | None) -> bool:
    """``[A-Za-z][\\w/]*`` without ``//`` (a package resource name, e.g. ``std_msgs/String``)."""
    if name is None:
        return False
    return _RESOURCE_NAME_LEGAL.fullmatch(name) is not None and "//" not in name


def is_legal_resource_base_name(name: str | None) -> bool:
    """``[A-Za-z]\\w*`` (a resource name without package, e.g. ``String``)."""
    return is_legal_base_name(name)


def normalize_package_context(package_context: str) -> str:
    """``' pkg// '`` -> ``'pkg'``."""
    return package_context.strip().rstrip(PRN_SEPARATOR)
