"""The tree keeps the shape docs/architecture.md describes: the import contracts' package lists
match stubs/, and the rules code-review-3 set for module sizes and duplicated operations hold.

The contracts themselves are checked by lint-imports (scripts/test.sh); these tests check that
what they are given is complete, which lint-imports cannot know: a package added to stubs/ and
not to root_packages is invisible to every contract, and a module of stubs/ that re-exports
behaviour and is not forbidden lets library code take behaviour from a ROS-named package."""

from __future__ import annotations

import ast
import re
import sys
from pathlib import Path

import pytest

if sys.version_info >= (3, 11):
    import tomllib
else:
    import tomli as tomllib

REPO = Path(__file__).resolve().parents[2]
STUBS = REPO / "stubs"
SRC = REPO / "src" / "minros"
IMPORTLINTER = tomllib.loads((REPO / "pyproject.toml").read_text())["tool"]["importlinter"]
#: the two contracts that keep behaviour out of the ROS-named packages
BEHAVIOUR_PREFIX = "Behaviour comes from minros.*"
#: the segments of a message module's name (std_msgs.msg, nodelet.srv, actionlib.msg ...)
MESSAGE_SEGMENTS = {"msg", "srv", "action"}


def _stub_packages() -> list:
    return [p.name for p in STUBS.iterdir() if (p / "__init__.py").is_file()]


def _stub_modules() -> dict:
    """Every module of stubs/, dotted name -> file."""
    out = {}
    for path in STUBS.rglob("*.py"):
        if "__pycache__" in path.parts:
            continue
        parts = list(path.relative_to(STUBS).with_suffix("").parts)
        if parts[-1] == "__init__":
            parts.pop()
        out[".".join(parts)] = path
    return out


def _behaviour_contracts() -> list:
    contracts = [c for c in IMPORTLINTER["contracts"] if c["name"].startswith(BEHAVIOUR_PREFIX)]
    assert len(contracts) == 2, [c["name"] for c in IMPORTLINTER["contracts"]]
    return contracts


def _imports(tree: ast.AST) -> set:
    found = set()
    for node in ast.walk(tree):
        if isinstance(node, ast.ImportFrom) and node.module:
            found.add(node.module)
        elif isinstance(node, ast.Import):
            found.update(alias.name for alias in node.names)
    return found


def _is_message_module(name: str, path: Path) -> bool:
    """A message module: under msg/srv/action and built from minros.msgs alone, or a package
    holding nothing but its docstring (std_msgs, sensor_msgs ...)."""
    tree = ast.parse(path.read_text())
    body = [n for n in tree.body
            if not (isinstance(n, ast.Expr) and isinstance(n.value, ast.Constant))]
    if not body:
        return True
    if MESSAGE_SEGMENTS & set(name.split(".")):
        return all(m == "minros.msgs" or m.startswith("minros.msgs.") for m in _imports(tree))
    return False


def test_root_packages_are_minros_and_the_listing_of_stubs():
    stubs = sorted(_stub_packages(), key=str.lower)
    assert IMPORTLINTER["root_packages"] == ["minros", *stubs], (
        "pyproject.toml's root_packages must be 'minros' and then every package of stubs/, "
        "sorted without regard to case")


def test_every_module_of_stubs_that_is_not_messages_is_forbidden_to_the_library():
    whole, exact = _behaviour_contracts()
    assert whole.get("as_packages", True) and exact.get("as_packages") is False
    packages = set(whole["forbidden_modules"])
    modules = set(exact["forbidden_modules"])
    stubs = _stub_modules()

    def forbidden(name: str) -> bool:
        parts = name.split(".")
        return name in modules or any(".".join(parts[:i]) in packages
                                      for i in range(1, len(parts) + 1))

    open_faces = sorted(name for name, path in stubs.items()
                        if not forbidden(name) and not _is_message_module(name, path))
    assert not open_faces, (
        f"{open_faces}: modules of stubs/ with behaviour that library code may import; add "
        "each to a forbidden list of the 'Behaviour comes from minros.*' contracts in "
        "pyproject.toml (the package, or the module alone when its messages must stay importable)")
    stale = sorted((packages | modules) - set(stubs))
    assert not stale, f"{stale}: forbidden in pyproject.toml but not modules of stubs/"


def test_the_exact_module_contract_forbids_only_packages_with_messages_inside():
    """as_packages = false is for a package whose msg/srv the library imports: any other
    belongs in the whole-package list, which also forbids its submodules."""
    _whole, exact = _behaviour_contracts()
    stubs = _stub_modules()
    for name in exact["forbidden_modules"]:
        inside = [m for m in stubs if m.startswith(name + ".")
                  and MESSAGE_SEGMENTS & set(m.split("."))]
        assert inside, f"{name} has no message modules: forbid it as a package"


@pytest.mark.parametrize("folder", ["cli", "master"])
def test_no_module_of_cli_or_the_master_is_over_800_lines(folder):
    sizes = {p.relative_to(SRC).as_posix(): len(p.read_text().splitlines())
             for p in (SRC / folder).rglob("*.py")}
    assert sizes
    assert not {name: n for name, n in sizes.items() if n > 800}


def test_rosbags_in_place_operation_is_written_once():
    definitions = [p.relative_to(SRC).as_posix() for p in SRC.rglob("*.py")
                   if re.search(r"^\s*def bag_op\(", p.read_text(), re.MULTILINE)]
    assert definitions == ["bag/ops.py"]
