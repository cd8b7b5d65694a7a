"""Packaging beyond pyproject.toml: one start-up file in site-packages, minros_import_hook.pth.

Everything else is declared in pyproject.toml. The .pth makes message packages on
ROS_PACKAGE_PATH importable before rospy (src/_minros_import_hook): setuptools has no
declarative way to put a file at the root of site-packages, so the two commands that build a
wheel add it, the regular one (build_py) and the editable one (editable_wheel, through the
step that writes namespace-package .pth files into the wheel; if a setuptools release drops
that step, an editable install simply lacks the hook and tests/unit/test_import_hook.py says
so).
"""

import os

from setuptools import setup
from setuptools.command.build_py import build_py
from setuptools.command.editable_wheel import editable_wheel

PTH_NAME = "minros_import_hook.pth"
PTH_TEXT = "import _minros_import_hook; _minros_import_hook.install()\n"


class BuildPyWithHook(build_py):
    def run(self) -> None:
        super().run()
        if not self.editable_mode:
            with open(os.path.join(self.build_lib, PTH_NAME), "w") as pth:
                pth.write(PTH_TEXT)

    def get_outputs(self, include_bytecode: bool = True) -> list:
        outputs = super().get_outputs(include_bytecode)
        if not self.editable_mode:
            outputs.append(os.path.join(self.build_lib, PTH_NAME))
        return outputs


class EditableWheelWithHook(editable_wheel):
    def _install_namespaces(self, installation_dir, pth_prefix) -> None:  # noqa: ANN001
        super()._install_namespaces(installation_dir, pth_prefix)
        with open(os.path.join(installation_dir, PTH_NAME), "w") as pth:
            pth.write(PTH_TEXT)


setup(cmdclass={"build_py": BuildPyWithHook, "editable_wheel": EditableWheelWithHook})
