"""Every bundled ROS 1 package whose definitions come from an upstream repository (Debian
lacks it) names the commit they were taken at, whole: a branch moves, a tag can be moved, and
an abbreviated hash grows ambiguous."""

from __future__ import annotations

import re

from minros.packages import BUILTIN_SHARE_DIRS


def test_upstream_definitions_name_a_full_commit():
    unnamed = []
    for copyright in sorted(BUILTIN_SHARE_DIRS[0].glob("*/COPYRIGHT*")):
        head = copyright.read_text()[:1500]
        intro = head.split("\n\n", 1)[0]  # the paragraph that says where the files come from
        if intro.startswith("Format: https://www.debian.org/"):
            continue  # Debian's copyright file: the definitions are Debian's package's
        if "https://github.com/" in intro and not re.search(r"\b[0-9a-f]{40}\b", intro):
            unnamed.append(copyright.parent.name)
    assert unnamed == []


def test_a_service_without_a_final_newline_parses():
    """turtlesim's Kill.srv ends in '---' with no newline, as upstream has it."""
    from minros.msgs import get_service_class

    kill = get_service_class("turtlesim/Kill")
    assert kill._md5sum == "c1f3d28f1b044c871e6eff2e9fc3c667"  # ROS's, as test_msgs_basic
    assert kill._response_class.__slots__ == []
