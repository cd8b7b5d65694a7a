"""camera_info_manager: a camera driver's calibration (sensor_msgs/CameraInfo), loaded from a
URL and saved by the ``set_camera_info`` service that calibration tools call, as ROS's
camera_info_manager_py does. Files are camera_calibration_parsers' YAML; URLs are
``file:///path``, ``package://pkg/path`` or empty (``$ROS_HOME/camera_info/<name>.yaml``), with
``${NAME}`` and ``${ROS_HOME}`` substituted."""

from __future__ import annotations

import os
import re
from pathlib import Path
from typing import Any, Optional, Tuple

import yaml

import minros
from minros import packages
from minros.rosenv import ros_home
from sensor_msgs.msg import CameraInfo
from sensor_msgs.srv import SetCameraInfo, SetCameraInfoResponse

__all__ = ["CameraInfoManager", "CameraInfoError", "CameraInfoMissingError", "genCameraName",
           "loadCalibrationFile", "parseURL", "resolveURL", "saveCalibration", "URL_empty",
           "URL_file", "URL_package", "URL_invalid", "default_camera_info_url"]

URL_empty, URL_file, URL_package, URL_invalid = 0, 1, 2, 3
default_camera_info_url = "file://${ROS_HOME}/camera_info/${NAME}.yaml"


class CameraInfoError(Exception):
    """A calibration that cannot be read or written."""


class CameraInfoMissingError(CameraInfoError):
    """getCameraInfo() before loadCameraInfo()."""


def genCameraName(from_string: str) -> str:  # noqa: N802 - ROS's name
    """A valid camera name: letters, digits and '_' (others become '_')."""
    return re.sub(r"[^A-Za-z0-9_]", "_", from_string)


def resolveURL(url: str, cname: str) -> str:  # noqa: N802
    """``url`` with ``${NAME}`` and ``${ROS_HOME}`` substituted."""
    return url.replace("${NAME}", cname).replace("${ROS_HOME}", str(ros_home()))


def parseURL(url: str) -> int:  # noqa: N802
    if url == "":
        return URL_empty
    if url.lower().startswith("file://"):
        return URL_file
    if url.lower().startswith("package://"):
        return URL_package
    return URL_invalid


def _path_of(url: str, cname: str) -> Optional[Path]:
    url = resolveURL(url or default_camera_info_url, cname)
    kind = parseURL(url)
    if kind == URL_file:
        return Path(url[len("file://"):])
    if kind == URL_package:
        package, _, rest = url[len("package://"):].partition("/")
        found = packages.find_package(package)
        return found / rest if found is not None and rest else None
    return None


def _matrix(values: Any, rows: int, cols: int) -> dict:
    return {"rows": rows, "cols": cols, "data": [float(v) for v in values]}


def to_yaml(cname: str, info: Any) -> str:
    """camera_calibration_parsers' YAML of a CameraInfo."""
    doc = {"image_width": int(info.width), "image_height": int(info.height),
           "camera_name": cname, "camera_matrix": _matrix(info.K, 3, 3),
           "distortion_model": info.distortion_model,
           "distortion_coefficients": _matrix(info.D, 1, len(info.D)),
           "rectification_matrix": _matrix(info.R, 3, 3),
           "projection_matrix": _matrix(info.P, 3, 4)}
    return yaml.safe_dump(doc, sort_keys=False, default_flow_style=None)


def from_yaml(text: str) -> Tuple[str, Any]:
    """(camera name, CameraInfo) of camera_calibration_parsers' YAML; CameraInfoError names
    the missing or malformed entry."""
    try:
        doc = yaml.safe_load(text)
    except yaml.YAMLError as exc:
        raise CameraInfoError(f"not YAML: {exc}") from None
    if not isinstance(doc, dict):
        raise CameraInfoError("a calibration file is a YAML mapping")
    info = CameraInfo()
    try:
        info.width, info.height = int(doc["image_width"]), int(doc["image_height"])
        for field, key, size in (("K", "camera_matrix", 9), ("R", "rectification_matrix", 9),
                                 ("P", "projection_matrix", 12)):
            data = [float(v) for v in doc[key]["data"]]
            if len(data) != size:
                raise CameraInfoError(f"{key} has {len(data)} values, not {size}")
            setattr(info, field, data)
        info.D = [float(v) for v in doc.get("distortion_coefficients", {}).get("data", [])]
        info.distortion_model = str(doc.get("distortion_model", "plumb_bob"))
    except (KeyError, TypeError, ValueError) as exc:
        raise CameraInfoError(f"missing or malformed entry {exc}") from None
    return str(doc.get("camera_name", "")), info


def loadCalibrationFile(url: str, cname: str) -> Any:  # noqa: N802
    """The CameraInfo at ``url`` (an empty one, with a warning, when the file is missing)."""
    path = _path_of(url, cname)
    if path is None:
        raise CameraInfoError(f"invalid camera calibration URL: {url}")
    if not path.exists():
        minros.logwarn(f"Camera calibration file {path} not found.")
        return CameraInfo()
    try:
        name, info = from_yaml(path.read_text())
    except (OSError, CameraInfoError) as exc:
        raise CameraInfoError(f"cannot read camera calibration {path}: {exc}") from None
    if name and name != cname:
        minros.logwarn(f"[{cname}] does not match name {name} in file {path}")
    return info


def saveCalibration(new_info: Any, url: str, cname: str) -> bool:  # noqa: N802
    path = _path_of(url, cname)
    if path is None:
        minros.logerr(f"invalid url: {url} (ignored)")
        return False
    try:
        path.parent.mkdir(parents=True, exist_ok=True)
        tmp = path.with_suffix(path.suffix + ".tmp")
        tmp.write_text(to_yaml(cname, new_info))
        os.replace(tmp, path)
    except OSError as exc:
        minros.logerr(f"cannot save camera calibration {path}: {exc}")
        return False
    return True


class CameraInfoManager:
    """Calibration of camera ``cname``: ``loadCameraInfo()`` reads ``url``; the
    ``<namespace>set_camera_info`` service stores a new one (and saves it to ``url``)."""

    def __init__(self, cname: str = "camera", url: str = "", namespace: str = "") -> None:
        self.cname = cname
        self.url = url
        self.camera_info: Optional[Any] = None
        self.svc = minros.Service(namespace + "set_camera_info", SetCameraInfo,
                                  self.setCameraInfo)

    def __str__(self) -> str:
        return f"[{self.cname}]{self.url}"

    def getCameraInfo(self) -> Any:
        if self.camera_info is None:
            raise CameraInfoMissingError("Calibration missing, loadCameraInfo() needed.")
        return self.camera_info

    def getCameraName(self) -> str:
        return self.cname

    def getURL(self) -> str:
        return self.url

    def isCalibrated(self) -> bool:
        if self.camera_info is None:
            raise CameraInfoMissingError("Calibration missing, loadCameraInfo() needed.")
        return self.camera_info.K[0] != 0.0

    def loadCameraInfo(self) -> None:
        self.camera_info = loadCalibrationFile(self.url, self.cname)

    def setCameraInfo(self, req: Any) -> Any:
        minros.logdebug("SetCameraInfo received for " + self.cname)
        self.camera_info = req.camera_info
        success = saveCalibration(req.camera_info, self.url, self.cname)
        return SetCameraInfoResponse(success=success,
                                     status_message="" if success else "Error storing camera calibration.")

    def setCameraName(self, cname: str) -> bool:
        if not cname or genCameraName(cname) != cname:
            return False
        self.cname = cname
        return True

    def setURL(self, url: str) -> bool:
        if parseURL(resolveURL(url, self.cname)) == URL_invalid:
            return False
        self.url = url
        return True
