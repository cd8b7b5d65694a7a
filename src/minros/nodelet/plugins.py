"""Which class a nodelet type names: the plugin files packages export, as pluginlib reads
them (``<export><nodelet plugin="${prefix}/nodelet_plugins.xml"/></export>``)."""

from __future__ import annotations

import importlib
import xml.etree.ElementTree as ET
from pathlib import Path
from typing import Dict, List, Tuple

from minros import packages

__all__ = ["NodeletTypeError", "declared_nodelets", "find_class"]


class NodeletTypeError(Exception):
    """A nodelet type that cannot be loaded; the message says why and what to do."""


def _plugin_files() -> List[Tuple[str, Path]]:
    out = []
    for pkg, pkg_dir in sorted(packages.list_packages().items()):
        manifest = pkg_dir / "package.xml"
        try:
            root = ET.parse(manifest).getroot()
        except (OSError, ET.ParseError):
            continue
        for export in root.findall("export"):
            for entry in export.findall("nodelet"):
                plugin = entry.get("plugin", "")
                if plugin:
                    out.append((pkg, Path(plugin.replace("${prefix}", str(pkg_dir)))))
    return out


def declared_nodelets() -> Dict[str, Tuple[str, str]]:
    """nodelet type (``pkg/Type``) -> (class type as written, plugin file)."""
    found: Dict[str, Tuple[str, str]] = {}
    for _pkg, path in _plugin_files():
        try:
            root = ET.parse(path).getroot()
        except (OSError, ET.ParseError):
            continue
        for cls in root.iter("class"):
            name = cls.get("name") or cls.get("type", "").replace("::", "/")
            if name and cls.get("base_class_type", "nodelet::Nodelet") == "nodelet::Nodelet":
                found[name] = (cls.get("type", ""), str(path))
    return found


def find_class(nodelet_type: str) -> type:
    """The Python class of ``nodelet_type``; raises NodeletTypeError naming the problem."""
    declared = declared_nodelets()
    if nodelet_type not in declared:
        known = ", ".join(sorted(declared)) or "none"
        raise NodeletTypeError(
            f"According to the loaded plugin descriptions the class {nodelet_type} with base "
            f"class type nodelet::Nodelet does not exist. Declared types are {known}")
    class_type, path = declared[nodelet_type]
    if "::" in class_type or "." not in class_type:
        raise NodeletTypeError(
            f"{nodelet_type} is a C++ nodelet ({class_type} in {path}); minros's manager loads "
            "Python nodelets only (type=\"python_module.ClassName\")")
    module_name, _, class_name = class_type.rpartition(".")
    try:
        module = importlib.import_module(module_name)
        cls = getattr(module, class_name)
    except (ImportError, AttributeError) as exc:
        raise NodeletTypeError(f"cannot load {class_type} for nodelet type {nodelet_type} "
                               f"(declared in {path}): {exc}") from None
    if not isinstance(cls, type):
        raise NodeletTypeError(f"{class_type} (nodelet type {nodelet_type}) is not a class")
    return cls
