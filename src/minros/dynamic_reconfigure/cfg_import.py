"""``<pkg>.cfg`` and ``<pkg>.cfg.<Name>Config`` modules from a package's ``cfg/*.cfg`` scripts.

Two ways in, one implementation: minros's message import hook (:mod:`minros.msgs.importer`)
asks :func:`find_spec` for packages on ROS_PACKAGE_PATH that have a ``cfg/`` folder, and
``catkin_make`` writes small modules into the devel space that call :func:`load_into`. Either
way the ``.cfg`` runs when the module is first imported, so an edited ``.cfg`` takes effect
on the next start of the node, without a build.
"""

from __future__ import annotations

import sys
from pathlib import Path
from types import ModuleType
from typing import Any, Dict, List

ModuleSpec = type(sys.__spec__)

STUB_PACKAGE = '"""{pkg}.cfg: dynamic_reconfigure configurations of {pkg} (written by minros catkin_make)."""\n'
STUB_MODULE = '''"""{pkg}.cfg.{module}: written by minros catkin_make; made from {path} on import."""

from minros.dynamic_reconfigure.cfg_import import load_into

load_into(globals(), {pkg!r}, {module!r}, {path!r})
'''


class _CfgPackageLoader:
    def create_module(self, spec: Any) -> None:
        return None

    def exec_module(self, module: ModuleType) -> None:
        module.__doc__ = f"{module.__name__}: dynamic_reconfigure configurations (minros)."


class _ConfigLoader:
    def __init__(self, package: str, package_dir: Path, module_name: str) -> None:
        self.package = package
        self.package_dir = package_dir
        self.module_name = module_name

    def create_module(self, spec: Any) -> None:
        return None

    def exec_module(self, module: ModuleType) -> None:
        from .generator import find_cfg

        path = find_cfg(self.package_dir, self.module_name)
        if path is None:
            # ImportError, not ModuleNotFoundError: `from pkg.cfg import X` would replace the
            # latter by a bare "cannot import name", losing where minros looked
            raise ImportError(
                f"No module named '{module.__name__}': package {self.package} has no "
                f"cfg/{self.module_name[:-len('Config')]}.cfg (nor a .cfg generating "
                f"{self.module_name})", name=module.__name__)
        _fill(module.__dict__, path, module.__name__)


def _fill(namespace: Dict[str, Any], path: Path, module_name: str) -> None:
    from .generator import CfgError, module_namespace, run_cfg

    try:
        gen = run_cfg(path)
    except CfgError as exc:
        raise ImportError(str(exc), name=module_name, path=str(path)) from None
    namespace.update(module_namespace(gen))
    namespace["__doc__"] = (f"{gen.name}Config: dynamic_reconfigure configuration of package "
                            f"{gen.pkgname}, made by minros from {path} on import.")


def find_spec(fullname: str, parts: List[str], package_dir: Path) -> Any:
    """The module spec of ``<pkg>.cfg`` or ``<pkg>.cfg.<Name>Config`` (None for anything else)."""
    if len(parts) == 2:
        spec = ModuleSpec(fullname, _CfgPackageLoader(), is_package=True)
        spec.submodule_search_locations = []
        return spec
    if len(parts) == 3 and parts[2].endswith("Config") and parts[2] != "Config":
        return ModuleSpec(fullname, _ConfigLoader(parts[0], package_dir, parts[2]))
    return None


def load_into(namespace: Dict[str, Any], package: str, module: str, built_from: str) -> None:
    """Fill a devel-space ``<pkg>.cfg.<Name>Config`` module: from the package's current
    ``.cfg`` if the package is on ROS_PACKAGE_PATH, else from the file catkin_make saw."""
    from minros import packages

    from .generator import find_cfg

    package_dir = packages.find_package(package)
    path = find_cfg(package_dir, module) if package_dir is not None else None
    _fill(namespace, path or Path(built_from), f"{package}.cfg.{module}")


def write_stubs(package: str, dist_packages: Path, modules: Dict[str, Path]) -> None:
    """Write ``<dist_packages>/<package>/cfg/{__init__,<Name>Config}.py`` for catkin_make."""
    folder = Path(dist_packages) / package / "cfg"
    folder.mkdir(parents=True, exist_ok=True)
    init = folder / "__init__.py"
    if not init.exists():
        init.write_text(STUB_PACKAGE.format(pkg=package))
    for module, path in modules.items():
        (folder / f"{module}.py").write_text(
            STUB_MODULE.format(pkg=package, module=module, path=str(path)))
