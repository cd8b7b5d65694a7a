"""minros's PEP 517 build backend: setuptools', with an editable install that is a plain .pth.

minros has two import roots, ``src/`` (minros) and ``stubs/`` (the packages under ROS names).
For a project with more than one root, setuptools' editable wheel installs an import hook
(``__editable___*_finder.py``) that ``sys.meta_path`` consults *after* Python's own path
finder. A folder named ``minros`` without an ``__init__.py`` in the current directory (the
folder of a clone, seen from its parent) is then found first, as a namespace package, and
``import minros``/``import rospy`` break (pypa/setuptools#3557). A ``.pth`` that puts both roots
on ``sys.path`` has no such order problem: Python prefers a regular package to namespace
portions wherever on the path they are. It is also what type checkers and IDEs understand.

Every hook is setuptools' own; ``build_editable`` only swaps setuptools' hook for the .pth in
the wheel it built. ``pip install -e . --config-settings editable_mode=strict`` (or any mode
asked for explicitly) is left to setuptools as it is.
"""

from __future__ import annotations

import base64
import hashlib
import os
import sys
import zipfile
from pathlib import Path

from setuptools import build_meta as _setuptools
from setuptools.build_meta import *  # noqa: F403  (every other hook is setuptools')

if sys.version_info >= (3, 11):
    import tomllib
else:
    import tomli as tomllib

PROJECT = Path(__file__).resolve().parent.parent


def _import_roots() -> list[Path]:
    """The folders [tool.setuptools.packages.find] searches (where packages live)."""
    with open(PROJECT / "pyproject.toml", "rb") as f:
        config = tomllib.load(f)
    where = config["tool"]["setuptools"]["packages"]["find"]["where"]
    return [(PROJECT / folder).resolve() for folder in where]


def _record_line(name: str, data: bytes) -> str:
    digest = base64.urlsafe_b64encode(hashlib.sha256(data).digest()).rstrip(b"=").decode()
    return f"{name},sha256={digest},{len(data)}"


def _static_pth(wheel_path: Path, roots: list[Path]) -> None:
    """Rewrite the editable wheel: setuptools' finder and its .pth out, ours in."""
    with zipfile.ZipFile(wheel_path) as wheel:
        members = {info.filename: wheel.read(info) for info in wheel.infolist()}
    hooks = [name for name in members if "/" not in name and name.startswith("__editable__")]
    if not any(name.endswith("_finder.py") for name in hooks):
        return  # setuptools chose a .pth itself (a single root): nothing to fix
    for name in hooks:
        del members[name]
    dist_info = next(name.split("/")[0] for name in members if name.endswith(".dist-info/RECORD"))
    pth_name = "__editable__." + dist_info[: -len(".dist-info")] + ".pth"
    members[pth_name] = "".join(f"{root}\n" for root in roots).encode()
    record_name = f"{dist_info}/RECORD"
    del members[record_name]
    # the .dist-info folder last, its RECORD (which lists every other file) at the very end
    order = sorted(members, key=lambda name: name.startswith(dist_info + "/"))
    members = {name: members[name] for name in order}
    record = [_record_line(name, data) for name, data in members.items()]
    record.append(f"{record_name},,")
    members[record_name] = ("\n".join(record) + "\n").encode()
    tmp = wheel_path.with_suffix(".tmp")
    with zipfile.ZipFile(tmp, "w", compression=zipfile.ZIP_DEFLATED) as wheel:
        for name, data in members.items():
            wheel.writestr(name, data)
    os.replace(tmp, wheel_path)


def build_editable(wheel_directory, config_settings=None, metadata_directory=None):  # noqa: ANN001, ANN201
    name = _setuptools.build_editable(wheel_directory, config_settings, metadata_directory)
    if not (config_settings or {}).get("editable_mode"):
        _static_pth(Path(wheel_directory, name), _import_roots())
    return name
