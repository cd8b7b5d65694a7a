"""The packaging: an editable install as the README makes it, and the wheel.

A clone lives in a folder named ``minros`` (``git clone ... minros``), which has no
``__init__.py``: from the folder that holds it, Python may see it as a namespace package
``minros``. These tests build that layout, install it the README's way (``pip install -e``,
with pip's build isolation, so the project's own build backend runs) and use it from there.
"""

from __future__ import annotations

import shutil
import subprocess
import sys
import sysconfig
import tarfile
import xmlrpc.client
import zipfile
from pathlib import Path

import pytest

from support import REPO, Proc, free_port, ros_env, wait_for_master, wait_until

#: what a clone has that building and installing reads (tests, docs, benchmarks are not read)
PROJECT_FILES = ("pyproject.toml", "README.md", "LICENSE", "MANIFEST.in", "build_backend",
                 "src", "stubs", "examples")

TALKER = """\
import rospy
from std_msgs.msg import String

rospy.init_node('talker', anonymous=True)
pub = rospy.Publisher('chatter', String, queue_size=10)
rate = rospy.Rate(10)
while not rospy.is_shutdown():
    pub.publish("hello world %s" % rospy.get_time())
    rate.sleep()
"""


def copy_project(dest: Path) -> Path:
    """The project's files copied to ``dest`` (a clone's worth, without caches)."""
    dest.mkdir(parents=True)
    for name in PROJECT_FILES:
        source = REPO / name
        if source.is_dir():
            shutil.copytree(source, dest / name,
                            ignore=shutil.ignore_patterns("__pycache__", "*.egg-info"))
        elif source.exists():
            shutil.copy2(source, dest / name)
    return dest


def pip(python: Path, *args: str, cwd: Path) -> None:
    done = subprocess.run([str(python), "-m", "pip", "--disable-pip-version-check", *args],
                          cwd=cwd, capture_output=True, text=True, timeout=600)
    assert done.returncode == 0, done.stdout[-3000:] + done.stderr[-3000:]


@pytest.fixture(scope="module")
def clone_parent(tmp_path_factory) -> tuple[Path, Path]:
    """(the folder holding a clone named ``minros``, the python of a venv with it installed
    editable). The venv gets minros itself through ``pip install -e``; its dependencies come
    from this test's environment (a .pth to its site-packages), so nothing is downloaded
    but the build backend's setuptools."""
    parent = tmp_path_factory.mktemp("home")
    clone = copy_project(parent / "minros")
    venv = parent / "venv"
    subprocess.run([sys.executable, "-m", "venv", str(venv)], check=True, timeout=300)
    python = venv / "bin" / "python"
    site = subprocess.run([str(python), "-c", "import sysconfig; print(sysconfig.get_paths()"
                           "['purelib'])"], capture_output=True, text=True, check=True,
                          timeout=60).stdout.strip()
    # a path line only: the .pth files there (this environment's own editable minros) are
    # not processed, as it is not a site directory
    Path(site, "zz_test_dependencies.pth").write_text(sysconfig.get_paths()["purelib"] + "\n")
    pip(python, "install", "--no-deps", "-e", str(clone), cwd=parent)
    return parent, python


def test_an_editable_install_imports_from_the_folder_holding_the_clone(clone_parent):
    parent, python = clone_parent
    probe = subprocess.run(
        [str(python), "-c", "import minros, rospy; print(minros.__file__); "
         "print(rospy.init_node.__module__)"],
        cwd=parent, capture_output=True, text=True, timeout=60, env=ros_env(None, parent))
    assert probe.returncode == 0, probe.stderr
    assert probe.stdout.split()[0] == str((parent / "minros/src/minros/__init__.py").resolve())


def test_roscore_and_a_talker_run_from_the_folder_holding_the_clone(clone_parent):
    parent, python = clone_parent
    (parent / "talker.py").write_text(TALKER)
    port = free_port()
    env = ros_env(port, parent / "ros_home")
    (parent / "ros_home" / "log").mkdir(parents=True)
    # `python -m` puts the current folder first on sys.path (the case that broke: roscore's
    # rosout is started so), and `python talker.py` the script's folder, here the same one
    core = Proc([str(python), "-m", "minros", "core", "-p", str(port)], env, cwd=parent)
    talker = None
    try:
        wait_for_master(port)
        master = xmlrpc.client.ServerProxy(f"http://127.0.0.1:{port}/")

        def subscribers(topic: str) -> list:
            _, _, (_pubs, subs, _srvs) = master.getSystemState("/test")
            return [nodes for name, nodes in subs if name == topic]

        wait_until(lambda: subscribers("/rosout"), 30, what="rosout subscribed to /rosout")
        talker = Proc([str(python), "talker.py"], env, cwd=parent)
        echo = subprocess.run([str(python), "-m", "minros", "topic", "echo", "-n", "1",
                               "/chatter"], cwd=parent, env=env, capture_output=True,
                              text=True, timeout=60)
        assert echo.returncode == 0, echo.stdout + echo.stderr
        assert "data: \"hello world" in echo.stdout
        assert core.alive()
    finally:
        if talker:
            talker.stop()
        core_output = core.stop()
    assert "Traceback" not in core_output, core_output


def test_the_wheel_carries_the_packages_and_the_sdist_the_examples(clone_parent, tmp_path):
    """A wheel is minros and the packages under ROS names, not the clone's examples/, which
    the README runs from a checkout; a source distribution carries them, and its own build
    backend, so a wheel builds from it."""
    parent, python = clone_parent
    project = parent / "minros"
    pip(python, "install", "setuptools>=77", cwd=parent)
    out = tmp_path / "dist"
    # what a build front-end does: the backend's hook, run in the source tree, backend-path
    # first on sys.path (pyproject.toml's [build-system])
    subprocess.run([str(python), "-c", "import sys; sys.path.insert(0, 'build_backend'); "
                    "import minros_build_backend as b; print(b.build_sdist(sys.argv[1]))",
                    str(out)], cwd=project, check=True, capture_output=True, timeout=300)
    (sdist,) = out.glob("minros-*.tar.gz")
    with tarfile.open(sdist) as tar:
        names = {name.split("/", 1)[1] for name in tar.getnames() if "/" in name}
    assert {"pyproject.toml", "README.md", "build_backend/minros_build_backend.py",
            "examples/README.md", "examples/sim/send_goal.py",
            "examples/talker_listener/talker.py", "src/minros/__init__.py",
            "stubs/rospy/__init__.py"} <= names
    assert not any("__pycache__" in name for name in names)
    pip(python, "wheel", "--no-deps", "-w", str(out), str(sdist), cwd=parent)
    (wheel,) = out.glob("minros-*.whl")
    with zipfile.ZipFile(wheel) as whl:
        names = set(whl.namelist())
    top = {name.split("/", 1)[0] for name in names}
    assert {"minros/__init__.py", "rospy/__init__.py", "std_msgs/__init__.py",
            "minros/msgs/share/std_msgs/msg/String.msg"} <= names
    assert not top & {"examples", "build_backend", "tests", "src", "stubs"}, sorted(top)
    readme = (REPO / "README.md").read_text()
    assert "python examples/" in readme
    assert "`examples/` are the checkout's" in readme  # and the README says where they are
