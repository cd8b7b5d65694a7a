"""catkin's run-time lookups (catkin.workspace, catkin.find_in_workspaces): which prefixes are
catkin workspaces, which source folders they were built from, and where a project's
``share``/``lib``/... folders are in them. roslib, roslaunch and rosmsg ask these at run time.

A workspace is a CMAKE_PREFIX_PATH entry holding a ``.catkin`` marker (its text: the source
folders, ``;``-separated), as a devel space ``catkin_make`` writes has. The last workspace is
the prefix of the packages minros bundles (its ``share/<pkg>`` folders), where a ROS install
has its system prefix.
"""

from __future__ import annotations

import os
from typing import Dict, List, Optional, Sequence

from minros.packages import BUILTIN_SHARE_DIRS

CATKIN_MARKER_FILE = ".catkin"

#: the prefixes of the packages minros bundles (``<prefix>/share/<pkg>``)
BUILTIN_PREFIXES = [str(share.parent) for share in BUILTIN_SHARE_DIRS]

_GLOBAL_DIRS = ["bin", "etc", "include", "lib", "share"]
_PROJECT_DIRS = ["etc", "include", "libexec", "share"]


def get_workspaces() -> List[str]:
    """The catkin workspaces on CMAKE_PREFIX_PATH, in order, then minros's bundled prefix."""
    paths = [p for p in os.environ.get("CMAKE_PREFIX_PATH", "").split(os.pathsep) if p]
    workspaces = [p for p in paths if os.path.isfile(os.path.join(p, CATKIN_MARKER_FILE))]
    return workspaces + [p for p in BUILTIN_PREFIXES if p not in workspaces]


def get_source_paths(workspace: str) -> List[str]:
    """The source folders a workspace was built from (read from its ``.catkin`` marker);
    none for minros's bundled prefix. ValueError for a folder that is not a workspace."""
    if workspace in BUILTIN_PREFIXES:
        return []
    marker = os.path.join(workspace, CATKIN_MARKER_FILE)
    if not os.path.isfile(marker):
        raise ValueError(f'Not a catkin workspace: "{workspace}", missing file {marker}')
    with open(marker) as f:
        data = f.read()
    paths: List[str] = []
    seen = set()
    for path in data.split(";") if data else []:
        real = os.path.realpath(path)
        if real not in seen:
            seen.add(real)
            paths.append(path)
    return paths


def _search_dirs(search_dirs: Optional[Sequence[str]], project: Optional[str]) -> List[str]:
    valid = _GLOBAL_DIRS if project is None else _PROJECT_DIRS
    if not search_dirs:
        return list(valid)
    dirs = list(search_dirs)
    unknown = set(dirs) - set(_GLOBAL_DIRS) - set(_PROJECT_DIRS)
    if unknown:
        raise ValueError("Unsupported search folders: " + ", ".join(f'"{d}"' for d in unknown))
    wrong = set(dirs) - set(valid)
    if wrong:
        raise ValueError(f"Searching {'without' if project is None else 'for'} a project can not "
                         "be combined with the search folders:"
                         + ", ".join(f'"{d}"' for d in wrong))
    return dirs


class _Found(Exception):
    """Ends the search at the first match (first_match_only)."""


def find_in_workspaces(search_dirs: Optional[Sequence[str]] = None, project: Optional[str] = None,
                       path: Optional[str] = None, _workspaces: Optional[List[str]] = None,
                       considered_paths: Optional[List[str]] = None,
                       first_matching_workspace_only: bool = False, first_match_only: bool = False,
                       workspace_to_source_spaces: Optional[Dict[str, List[str]]] = None,
                       source_path_to_packages: Optional[Dict[str, dict]] = None) -> List[str]:
    """The existing folders ``<workspace>/<search dir>[/<project>][/<path>]`` of every
    workspace in order; for ``share`` of a project also the project's folder in the
    workspace's source spaces. ``considered_paths`` collects every candidate; the two caches
    spare re-reading markers and re-crawling sources across calls."""
    from catkin_pkg.packages import find_packages

    dirs = _search_dirs(search_dirs, project)
    if "libexec" in dirs:
        dirs.insert(dirs.index("libexec"), "lib")
    workspaces = get_workspaces() if _workspaces is None else _workspaces
    sources = {} if workspace_to_source_spaces is None else workspace_to_source_spaces
    crawled = {} if source_path_to_packages is None else source_path_to_packages
    candidates: List[str] = []
    existing: List[str] = []

    def consider(candidate: str) -> None:
        candidates.append(candidate)
        if os.path.exists(candidate):
            existing.append(candidate)
            if first_match_only:
                raise _Found

    try:
        for workspace in workspaces or []:
            for sub in dirs:
                candidate = os.path.join(workspace, sub)
                if project:
                    candidate = os.path.join(candidate, project)
                if path:
                    candidate = os.path.join(candidate, path)
                consider(candidate)
                if project is None or sub != "share":
                    continue
                if workspace not in sources:
                    sources[workspace] = get_source_paths(workspace)
                for source in sources[workspace]:
                    if source not in crawled:
                        crawled[source] = find_packages(source)
                    matching = [rel for rel, pkg in crawled[source].items() if pkg.name == project]
                    if not matching:
                        continue
                    candidate = source if matching[0] == os.curdir else os.path.join(source, matching[0])
                    if path is not None:
                        candidate = os.path.join(candidate, path)
                    consider(candidate)
            if first_matching_workspace_only and existing:
                break
    except _Found:
        pass
    if considered_paths is not None:
        considered_paths.extend(candidates)
    return existing
