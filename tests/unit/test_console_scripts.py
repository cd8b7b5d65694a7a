"""minros's console scripts and those of the distributions installed beside it: pip writes a
script for each, and the one installed last overwrites the other's file (uninstalling minros
then deletes it: PyPI's xacro lost its ``xacro``), so minros takes no name another has, but
for the two it replaces on purpose."""

from __future__ import annotations

from importlib.metadata import distributions

#: scripts minros replaces knowingly (pyproject.toml notes each): rospkg's rosversion, which
#: cannot see the packages minros provides, and catkin_pkg's catkin_create_pkg (minros ws
#: create_pkg); left as they are for now
REPLACED = {"rosversion", "catkin_create_pkg"}


def _scripts() -> dict:
    owners: dict = {}
    for dist in distributions():
        for entry in dist.entry_points:
            if entry.group in ("console_scripts", "gui_scripts"):
                owners.setdefault(entry.name, set()).add(dist.metadata["Name"].lower())
    return owners


def test_no_console_script_of_minros_is_another_distributions() -> None:
    owners = _scripts()
    assert "xacro-noetic" in {name for name, who in owners.items() if "minros" in who}
    shared = {name for name, who in owners.items() if "minros" in who and len(who) > 1}
    assert shared - REPLACED == set(), {name: owners[name] for name in shared}
