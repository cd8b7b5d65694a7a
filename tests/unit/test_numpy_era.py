"""What minros depends on lets ROS-era numpy code run (README: "numpy 2 and ROS-era code"):
``ndarray.tostring()``, which cv_bridge's own tests, ros_numpy and genpy's generated
``serialize_numpy`` call, exists on the numpy minros installs, on every Python CI runs."""

from __future__ import annotations

import importlib.metadata
import re
import warnings

import numpy as np

from support import REPO


def test_tostring_is_there_and_is_tobytes():
    image = np.arange(24, dtype=np.uint16).reshape(2, 3, 4)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", DeprecationWarning)
        assert image.tostring() == image.tobytes()


def test_genpys_numpy_serialization_runs(tmp_path):
    """A module generated as genpy generates it (minros.msgs.pygen, genpy's text line for line)
    serializes a numpy array field with tostring()."""
    import importlib.util
    import io

    from minros.msgs.pygen import MsgGenerator
    from minros.packages import find_package

    msg_dir = find_package("std_msgs") / "msg"
    assert MsgGenerator().generate_messages(
        "std_msgs", [str(msg_dir / "Float32MultiArray.msg")], str(tmp_path),
        {"std_msgs": [str(msg_dir)]}) == 0
    path = tmp_path / "_Float32MultiArray.py"
    assert ".tostring()" in path.read_text()
    spec = importlib.util.spec_from_file_location("genpy_float32multiarray", path)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    msg = module.Float32MultiArray(data=np.array([1.5, 2.5], dtype=np.float32))
    buff = io.BytesIO()
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", DeprecationWarning)
        msg.serialize_numpy(buff, np)
    assert buff.getvalue().endswith(np.array([1.5, 2.5], dtype="<f4").tobytes())


def test_the_dependency_and_the_readme_agree():
    requires = importlib.metadata.requires("minros") or []
    numpy_req = next(r for r in requires if re.match(r"numpy\b", r))
    assert "<2.3" in numpy_req.replace(" ", "")
    readme = (REPO / "README.md").read_text()
    assert "### numpy 2 and ROS-era code" in readme and "`numpy>=1.21,<2.3`" in readme
