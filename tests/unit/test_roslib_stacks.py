"""roslib.manifestlib, roslib.stack_manifest and roslib.stacks over minros's package lookup:
rosbuild manifests parsed field by field (the same fields as Debian's roslib reads), stacks
found on ROS_PACKAGE_PATH."""

from __future__ import annotations

import json
import subprocess
from pathlib import Path

import pytest

import roslib.manifestlib as manifestlib
import roslib.stack_manifest as stack_manifest
import roslib.stacks as stacks
from minros import packages
from support import REFERENCE_PYTHON, need, reference_env, reference_imports

MANIFEST = """<package>
  <description brief="A demo">Demo <b>package</b></description>
  <author>Ann Author</author>
  <license url="http://opensource.org/licenses/BSD-3-Clause">BSD</license>
  <review status="doc reviewed" notes="fine"/>
  <url>http://example.com/demo</url>
  <depend package="roscpp"/>
  <depend package="std_msgs"/>
  <rosdep name="boost"/>
  <platform os="ubuntu" version="9.04"/>
  <export><cpp cflags="-I${prefix}/include"/><python path="${prefix}/src"/></export>
  <versioncontrol type="git" url="https://example.com/demo.git"/>
  <frob/>
</package>
"""

STACK = """<stack>
  <description>Tools</description>
  <author>Ann Author</author>
  <license>BSD</license>
  <depend stack="ros"/>
  <version>1.4.2</version>
</stack>
"""


@pytest.fixture
def workspace(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> Path:
    stack = tmp_path / "src" / "tools_stack"
    (stack / "demo").mkdir(parents=True)
    (stack / STACK_FILE_NAME).write_text(STACK)
    (stack / "demo" / "manifest.xml").write_text(MANIFEST)
    meta = tmp_path / "src" / "my_meta"
    meta.mkdir()
    (meta / "package.xml").write_text(
        '<package format="2"><name>my_meta</name><version>0.3.0</version><description>m</description>'
        '<maintainer email="a@b.c">a</maintainer><license>BSD</license>'
        '<buildtool_depend>catkin</buildtool_depend><exec_depend>demo</exec_depend>'
        '<export><metapackage/></export></package>')
    monkeypatch.setenv("ROS_PACKAGE_PATH", str(tmp_path / "src"))
    packages.list_packages(refresh=True)
    return tmp_path


STACK_FILE_NAME = "stack.xml"


def test_manifestlib_reads_every_field():
    m = manifestlib.parse(manifestlib._Manifest(), MANIFEST, "demo/manifest.xml")
    assert m.description == "Demo <b>package</b>" and m.brief == "A demo"
    assert (m.author, m.license) == ("Ann Author", "BSD")
    assert m.license_url.endswith("BSD-3-Clause")
    assert (m.status, m.notes, m.url) == ("doc reviewed", "fine", "http://example.com/demo")
    assert [d.package for d in m.depends] == ["roscpp", "std_msgs"]
    assert [r.name for r in m.rosdeps] == ["boost"]
    assert m.platforms == [manifestlib.Platform("ubuntu", "9.04")]
    assert m.get_export("python", "path") == ["${prefix}/src"]
    assert (m.versioncontrol.type, m.versioncontrol.url) == ("git", "https://example.com/demo.git")
    assert [t.tagName for t in m.unknown_tags] == ["frob"]
    # what xml() writes parses back to the same fields
    again = manifestlib.parse(manifestlib._Manifest(), m.xml())
    assert [d.package for d in again.depends] == ["roscpp", "std_msgs"]
    assert again.get_export("cpp", "cflags") == ["-I${prefix}/include"]


def test_manifestlib_errors_name_the_problem(tmp_path: Path):
    with pytest.raises(manifestlib.ManifestException, match="invalid XML"):
        manifestlib.parse(manifestlib._Manifest(), "<package>")
    with pytest.raises(manifestlib.ManifestException, match="missing required 'license'"):
        manifestlib.parse(manifestlib._Manifest(), "<package><author>a</author></package>", "x.xml")
    bad = tmp_path / "manifest.xml"
    bad.write_text("<stack/>")
    with pytest.raises(manifestlib.ManifestException, match=str(bad)):
        manifestlib.parse_file(manifestlib._Manifest(), str(bad))
    with pytest.raises(ValueError, match="non-existent"):
        manifestlib.parse_file(manifestlib._Manifest(), str(tmp_path / "nope.xml"))
    with pytest.raises(manifestlib.ManifestException, match="not allowed"):
        stack_manifest.parse(STACK.replace("</stack>", "<rosdep name='x'/></stack>"))


def test_stacks_on_the_package_path(workspace: Path):
    assert sorted(stacks.list_stacks()) == ["my_meta", "tools_stack"]
    assert stacks.get_stack_dir("tools_stack") == str(workspace / "src" / "tools_stack")
    with pytest.raises(stacks.InvalidROSStackException):
        stacks.get_stack_dir("no_such_stack")
    assert stacks.stack_of("demo") == "tools_stack"
    assert stacks.stack_of("my_meta") is None
    assert stacks.get_stack_version("tools_stack") == "1.4.2"
    assert stacks.get_stack_version("my_meta") == "0.3.0"
    cache: dict = {}
    assert stacks.list_stacks_by_path(str(workspace), cache=cache) == ["tools_stack"]
    assert cache == {"tools_stack": str(workspace / "src" / "tools_stack")}
    found, missing = stacks.expand_to_packages(["tools_stack", "my_meta", "nothing"])
    assert "demo" in found and missing == ["nothing"]
    path = stack_manifest.stack_file("tools_stack")
    m = stack_manifest.parse_file(path)
    assert [d.stack for d in m.depends] == ["ros"] and m.version == "1.4.2"


@pytest.mark.slow
@pytest.mark.interop
def test_same_fields_as_debians_roslib():
    need(reference_imports("roslib.manifestlib"), "Debian's roslib", "scripts/install-ros-reference.sh")
    code = ("import json, sys, roslib.manifestlib as ml\n"
            "m = ml.parse(ml._Manifest(), sys.stdin.read())\n"
            "print(json.dumps([m.description, m.brief, m.author, m.license, m.license_url, m.status,"
            " m.notes, m.url, [d.package for d in m.depends], [r.name for r in m.rosdeps],"
            " [str(p) for p in m.platforms], [(e.tag, e.attrs) for e in m.exports],"
            " [m.versioncontrol.type, m.versioncontrol.url]]))\n")
    theirs = subprocess.run([REFERENCE_PYTHON, "-c", code], input=MANIFEST, capture_output=True,
                            text=True, env=reference_env({}), timeout=60, check=True)
    m = manifestlib.parse(manifestlib._Manifest(), MANIFEST)
    ours = [m.description, m.brief, m.author, m.license, m.license_url, m.status, m.notes, m.url,
            [d.package for d in m.depends], [r.name for r in m.rosdeps],
            [str(p) for p in m.platforms], [[e.tag, e.attrs] for e in m.exports],
            [m.versioncontrol.type, m.versioncontrol.url]]
    assert json.loads(theirs.stdout) == ours
