"""docs/architecture.md is the map, and says what is true: every path its tables name exists,
every package and module of src/minros/ is in a table, every module that keeps state at module
level is marked "module global" in its row, and the `trace.watch` sites it names are the ones
the code has."""

from __future__ import annotations

import ast
import functools
import re
from pathlib import Path
from typing import Dict, FrozenSet, List, Set, Tuple

REPO = Path(__file__).resolve().parents[2]
SRC = REPO / "src" / "minros"
DOC = (REPO / "docs" / "architecture.md").read_text()
#: a path in backticks that starts at the repository's root
PATH = re.compile(r"`((?:src|stubs|tests|examples|build_backend|scripts|docs|benchmarks)/[^`\s]*)`")
#: folders whose every module has a row of its own (or its sub-folder's)
EVERY_MODULE = ["wire", "transport", "node", "master", "client", "tools", "msgs", "ros2/types",
                "ros2/rtps", "ros2/rmw", "ros2/bridge", "bag", "web", "zenoh", "launch"]
#: module-level calls that make mutable state
MUTABLE_CALLS = {"dict", "list", "set", "defaultdict", "OrderedDict", "deque", "Counter",
                 "WeakSet", "WeakValueDictionary", "WeakKeyDictionary", "Lock", "RLock",
                 "Condition", "Event", "local", "count"}

# Paths the page may name before they are in the tree (a branch that brings them merges after
# the page), and paths in the tree the page no longer describes (a branch removes them): both
# empty while page and tree agree.
#: named by the page, not yet in the tree
NOT_YET: Set[str] = set()
#: in the tree, no longer described
GOING: Set[str] = set()


def _rows() -> List[str]:
    return [line for line in DOC.splitlines() if line.startswith("| `")]


def _named(lines: List[str]) -> Set[str]:
    return {m.group(1) for line in lines for m in PATH.finditer(line)}


@functools.cache
def _names_by_row() -> Tuple[Tuple[str, FrozenSet[str]], ...]:
    return tuple((line, frozenset(_named([line]))) for line in _rows())


def _row_of(rel: str) -> str:
    """The table row naming this file, or its nearest folder."""
    best, length = "", -1
    for line, names in _names_by_row():
        for name in names:
            folder = name.endswith("/") and name.startswith("src/minros/")
            if (name == rel or (folder and rel.startswith(name))) and len(name) > length:
                best, length = line, len(name)
    return best


#: a line that may start such state (the modules without one are not parsed: it is cheaper)
CANDIDATE = re.compile(r"^(?:\s+global\s|@.*cache|(?!__)(?=\w*[a-z])\w+\s*(?::[^=\n]*)?=\s*"
                       r"(?:[\[{]|[\w.]*(?:" + "|".join(sorted(MUTABLE_CALLS)) + r")\(|(?:\w+\.)*[A-Z]\w*\())",
                       re.MULTILINE)


def _module_state(path: Path) -> List[str]:
    """The names a module keeps mutable state in at module level: containers, locks, counters
    and instances of classes bound to a name that is not a constant's, names a `global`
    statement rebinds, and functools caches."""
    text = path.read_text()
    if not CANDIDATE.search(text):
        return []
    tree = ast.parse(text)
    rebound = {name for node in ast.walk(tree) if isinstance(node, ast.Global)
               for name in node.names}
    found = sorted(rebound)
    for node in tree.body:
        if isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef)):
            if any("cache" in ast.unparse(d) for d in node.decorator_list):
                found.append(node.name)
            continue
        if isinstance(node, ast.Assign):
            targets, value = node.targets, node.value
        elif isinstance(node, ast.AnnAssign) and node.value is not None:
            targets, value = [node.target], node.value
        else:
            continue
        for target in targets:
            if not isinstance(target, ast.Name) or target.id.isupper() or target.id.startswith("__"):
                continue
            if isinstance(value, (ast.Dict, ast.List, ast.Set)):
                found.append(target.id)
            elif isinstance(value, ast.Call):
                func = value.func
                called = func.attr if isinstance(func, ast.Attribute) else getattr(func, "id", "")
                if called in MUTABLE_CALLS or called[:1].isupper():
                    found.append(target.id)
    return found


def test_every_path_the_page_names_exists():
    named = _named(DOC.splitlines())
    assert len(named) > 150
    missing = sorted(n for n in named if not (REPO / n).exists())
    assert set(missing) <= NOT_YET, f"docs/architecture.md names what is not in the tree: {missing}"


def test_every_package_and_module_of_src_minros_is_in_a_table():
    named = _named(_rows())
    entries = [p for p in SRC.iterdir() if p.suffix == ".py" or (p / "__init__.py").is_file()]
    absent = sorted(p.relative_to(REPO).as_posix() for p in entries
                    if not any(n == p.relative_to(REPO).as_posix()
                               or n.startswith(p.relative_to(REPO).as_posix() + "/")
                               for n in named))
    assert not absent, f"no row of docs/architecture.md's tables names {absent}"


def test_the_core_layers_name_every_module():
    absent = []
    for folder in EVERY_MODULE:
        for path in sorted((SRC / folder).rglob("*.py")):
            rel = path.relative_to(REPO).as_posix()
            if path.name == "__init__.py" and path.parent != SRC / "node":
                continue
            if rel not in GOING and not _row_of(rel):
                absent.append(rel)
    assert not absent, f"docs/architecture.md has no row for {absent}"


def test_every_module_that_keeps_state_at_module_level_says_so():
    unmarked: Dict[str, List[str]] = {}
    for path in sorted(SRC.rglob("*.py")):
        rel = path.relative_to(REPO).as_posix()
        state = _module_state(path)
        if not state or rel in GOING:
            continue
        row = _row_of(rel)
        if "module global" not in row and "functools.cache" not in row:
            unmarked[rel] = state
    assert not unmarked, ("modules with state at module level whose row in docs/architecture.md "
                          f"does not say 'module global': {unmarked}")


def test_the_trace_watch_sites_are_the_ones_named():
    sites = {p.relative_to(REPO).as_posix() for p in SRC.rglob("*.py")
             if "trace.watch(" in p.read_text()}
    paragraph = DOC[DOC.index("The `trace.watch` sites"):]
    paragraph = paragraph[:paragraph.index("\n\n")]
    named = {n for n in _named([paragraph]) if n not in NOT_YET or (REPO / n).exists()}
    assert sites - GOING == named, (sites, named)
