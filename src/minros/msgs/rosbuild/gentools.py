"""roslib.gentools: md5 sums and full texts over roslib.msgs' table of registered types.

``get_dependencies`` loads (and registers) every type a spec embeds that its package may
see (itself and its dependencies, as rospack lists them) and returns roslib's dependency
dict: ``spec``, ``package``, ``deps`` (in field order, repeats kept), ``uniquedeps`` and,
unless ``compute_files=False``, ``files``. The md5 text is genmsg's.
"""

from __future__ import annotations

import hashlib
import sys
from io import StringIO
from typing import Any, Dict, List, Optional

from minros import names as _names

from .. import spec as _spec
from . import msgs as _msgs
from . import srvs as _srvs

_header_type_name = "std_msgs/Header"


def _valid_packages(package_context: str, rospack: Any) -> List[str]:
    """The packages whose types ``package_context``'s messages may embed: itself and what it
    depends on (a missing package being generated sees only itself)."""
    from minros import packages

    return ["", package_context] + packages.reachable_packages(package_context)


def _add_msgs_depends(rospack: Any, spec: Any, deps: List[str], package_context: str) -> None:
    """Append the types ``spec`` embeds to ``deps``, depth first, loading unregistered ones."""
    valid: Optional[List[str]] = None
    for type_ in spec.types:
        base = _msgs.base_msg_type(type_) or type_
        if _msgs.is_builtin(base):
            continue
        if base == _msgs.HEADER:
            deps.append(_header_type_name)
        if _msgs.is_registered(base):
            dep_spec = _msgs.get_registered(base)
            if base != _msgs.HEADER:
                deps.append(base if "/" in base else f"{package_context}/{base}")
        else:
            if valid is None:
                valid = _valid_packages(package_context, rospack)
            dep_package, _ = _names.package_resource_name(base)
            if dep_package not in valid:
                raise KeyError(base)
            key, dep_spec = _msgs.load_by_type(base, package_context)
            if base != _msgs.HEADER:
                deps.append(key)
            _msgs.register(key, dep_spec)
        _add_msgs_depends(rospack, dep_spec, deps, package_context)


def get_dependencies(spec: Any, package: str, compute_files: bool = True, stdout: Any = sys.stdout,
                     stderr: Any = sys.stderr, rospack: Any = None) -> Dict[str, Any]:
    """The dependency dict of a message or service spec in ``package``."""
    _msgs._init()
    deps: List[str] = []
    try:
        if rospack is None:
            from minros import packages

            rospack = packages.rospack()
        if isinstance(spec, _msgs.MsgSpec):
            _add_msgs_depends(rospack, spec, deps, package)
        elif isinstance(spec, _srvs.SrvSpec):
            _add_msgs_depends(rospack, spec.request, deps, package)
            _add_msgs_depends(rospack, spec.response, deps, package)
        else:
            raise _msgs.MsgSpecException("spec does not appear to be a message or service")
    except KeyError as exc:
        raise _msgs.MsgSpecException(
            f"Cannot load type {exc}.  Perhaps the package is missing a dependency.") from None
    uniquedeps = list(dict.fromkeys(deps))
    out: Dict[str, Any] = {"deps": deps, "spec": spec, "package": package, "uniquedeps": uniquedeps}
    if compute_files:
        files = {}
        for dep in set(deps):
            dep_package, base = _names.package_resource_name(dep)
            files[dep] = _msgs.msg_file(dep_package or package, base)
        out["files"] = files
    return out


def get_file_dependencies(f: str, stdout: Any = sys.stdout, stderr: Any = sys.stderr,
                          rospack: Any = None) -> Dict[str, Any]:
    """:func:`get_dependencies` of a ``.msg`` or ``.srv`` file, in the package holding it."""
    import rospkg

    package = rospkg.get_package_name(f)
    spec: Any
    if f.endswith(_msgs.EXT):
        _, spec = _msgs.load_from_file(f)
    elif f.endswith(_srvs.EXT):
        _, spec = _srvs.load_from_file(f)
    else:
        raise Exception(f"[{f}] does not appear to be a message or service")
    return get_dependencies(spec, package, stdout=stdout, stderr=stderr, rospack=rospack)


def compute_md5_text(get_deps_dict: Dict[str, Any], spec: Any, rospack: Any = None) -> str:
    """The text a message's md5 is taken of: constants, then fields, an embedded type's field
    replaced by that type's md5 (genmsg's rule)."""
    package = get_deps_dict["package"]
    compute_files = "files" in get_deps_dict
    buff = StringIO()
    for c in spec.constants:
        buff.write(f"{c.type} {c.name}={c.val_text}\n")
    for type_, name in zip(spec.types, spec.names):
        base = _msgs.base_msg_type(type_) or type_
        if _msgs.is_builtin(base):
            buff.write(f"{type_} {name}\n")
            continue
        if base == _msgs.HEADER:
            base = _header_type_name
        sub_package = _names.package_resource_name(base)[0] or package
        sub_spec = _msgs.get_registered(base, package)
        sub_deps = get_dependencies(sub_spec, sub_package, compute_files=compute_files,
                                    rospack=rospack)
        buff.write(f"{compute_md5(sub_deps, rospack)} {name}\n")
    return buff.getvalue().strip()


def _compute_hash(get_deps_dict: Dict[str, Any], hash: Any, rospack: Any = None) -> str:  # noqa: A002
    spec = get_deps_dict["spec"]
    if isinstance(spec, _msgs.MsgSpec):
        hash.update(compute_md5_text(get_deps_dict, spec, rospack=rospack).encode())
    elif isinstance(spec, _srvs.SrvSpec):
        hash.update(compute_md5_text(get_deps_dict, spec.request, rospack=rospack).encode())
        hash.update(compute_md5_text(get_deps_dict, spec.response, rospack=rospack).encode())
    else:
        raise Exception(f"[{spec}] is not a message or service")
    return hash.hexdigest()


def compute_md5(get_deps_dict: Dict[str, Any], rospack: Any = None) -> str:
    """The md5 sum of the dict's message or service."""
    return _compute_hash(get_deps_dict, hashlib.md5(), rospack=rospack)


compute_md5_v2 = compute_md5


def compute_md5_v1(get_deps_dict: Dict[str, Any]) -> str:
    """The md5 sum of ROS before 0.6: of the texts themselves."""
    digest = hashlib.md5(get_deps_dict["spec"].text.encode())
    for dep in get_deps_dict["uniquedeps"]:
        digest.update(_msgs.get_registered(dep).text.encode())
    return digest.hexdigest()


def compute_full_text(get_deps_dict: Dict[str, Any]) -> str:
    """The message_definition: the text, then each embedded type's after a separator line and
    ``MSG: pkg/Type``."""
    parts = [get_deps_dict["spec"].text]
    for dep in get_deps_dict["uniquedeps"]:
        parts += [_spec.SEPARATOR, f"MSG: {dep}", _msgs.get_registered(dep).text]
    return "\n".join(parts)
