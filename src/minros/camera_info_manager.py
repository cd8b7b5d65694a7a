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
           "URL_file", "URL_package", "URL_invalid", "default_camera_info_url", "parse_ini",
           "readCalibration"]

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


# ---------------------------------------------------------------------------------------------
# camera_calibration_parsers: read a calibration file, YAML or the legacy Videre INI format, as
# its C++ readers read them

_INI_REAL = re.compile(r"([+-]?)(?:(\d+)\.?(\d*)|\.(\d+))(?:[eE]([+-]?\d+))?")
_INI_UINT = re.compile(r"\d+")


class _IniScanner:
    """A cursor over an INI calibration: whitespace and ``#`` comments skipped before each
    token, as the C++ grammar's skipper does."""

    def __init__(self, text: str) -> None:
        self.text = text
        self.pos = 0

    def skip(self) -> None:
        while self.pos < len(self.text):
            if self.text[self.pos].isspace():
                self.pos += 1
            elif self.text[self.pos] == "#":
                end = self.text.find("\n", self.pos)
                self.pos = len(self.text) if end < 0 else end + 1
            else:
                return

    def literal(self, word: str) -> bool:
        self.skip()
        if self.text.startswith(word, self.pos):
            self.pos += len(word)
            return True
        return False

    def expect(self, word: str) -> None:
        if not self.literal(word):
            raise CameraInfoError(f"INI calibration: expected '{word}' at offset {self.pos}")

    def number(self, pattern: re.Pattern, what: str) -> float:
        self.skip()
        match = pattern.match(self.text, self.pos)
        if match is None:
            raise CameraInfoError(f"INI calibration: expected {what} at offset {self.pos}")
        self.pos = match.end()
        return _spirit_real(match) if pattern is _INI_REAL else float(match.group())

    def reals(self, count: int) -> list:
        return [self.number(_INI_REAL, "a number") for _ in range(count)]


def _spirit_real(match: re.Match) -> float:
    """The number as the C++ parser (Boost.Spirit's real_p) computes it: the fraction's digits
    as an integer times 10^-digits added to the integer part, then scaled by the exponent, so
    that a value reads back to the same double C++ gets (0.33758 -> 0.33758000000000005)."""
    sign, whole, frac, only_frac, exponent = match.groups()
    frac = frac if only_frac is None else only_frac
    value = float(int(whole or "0"))
    if frac:
        value += int(frac) * 10.0 ** -len(frac)
    if exponent:
        value *= 10.0 ** int(exponent)
    return -value if sign == "-" else value


def parse_ini(text: str) -> Tuple[str, Any]:
    """(camera name, CameraInfo) of a Videre INI calibration: ``[image]`` width and height,
    an optional ``[externals]`` section, then the camera's section with its camera matrix,
    distortion (5 values: plumb_bob, 8: rational_polynomial), rectification and projection."""
    scan = _IniScanner(text)
    info = CameraInfo()
    scan.expect("[image]")
    scan.expect("width")
    info.width = int(scan.number(_INI_UINT, "the width"))
    scan.expect("height")
    info.height = int(scan.number(_INI_UINT, "the height"))
    if scan.literal("[externals]"):
        scan.expect("translation")
        scan.reals(3)
        scan.expect("rotation")
        scan.reals(3)
    scan.expect("[")
    end = scan.text.find("]", scan.pos)
    if end < 0:
        raise CameraInfoError("INI calibration: the camera section's name has no ']'")
    name = scan.text[scan.pos:end]
    scan.pos = end + 1
    scan.expect("camera matrix")
    info.K = scan.reals(9)
    scan.expect("distortion")
    distortion = []
    while True:
        scan.skip()
        match = _INI_REAL.match(scan.text, scan.pos)
        if match is None:
            break
        distortion.append(_spirit_real(match))
        scan.pos = match.end()
    info.D = distortion
    scan.expect("rectification")
    info.R = scan.reals(9)
    scan.expect("projection")
    info.P = scan.reals(12)
    info.distortion_model = {5: "plumb_bob", 8: "rational_polynomial"}.get(len(distortion), "")
    return name, info


def _parse_calibration_yaml(text: str) -> Tuple[str, Any]:
    """camera_calibration_parsers' YAML reader: the name defaults to "unknown", the distortion
    model to plumb_bob, and the distortion's rows x cols values are read."""
    name, info = from_yaml(text)
    doc = yaml.safe_load(text)
    try:
        distortion = doc["distortion_coefficients"]
        count = int(distortion["rows"]) * int(distortion["cols"])
        info.D = [float(v) for v in distortion["data"][:count]]
        if len(info.D) != count:
            raise CameraInfoError(f"distortion_coefficients has {len(info.D)} values, not {count}")
    except (KeyError, TypeError, ValueError) as exc:
        raise CameraInfoError(f"missing or malformed entry {exc}") from None
    return (name if "camera_name" in doc else "unknown"), info


def readCalibration(file_name: str) -> Optional[Tuple[str, Any]]:  # noqa: N802 - ROS's name
    """(camera name, CameraInfo) from a ``.yaml``/``.yml`` or ``.ini`` calibration file, or
    None when it cannot be read (camera_calibration_parsers.readCalibration)."""
    lower = file_name.lower()
    parse = (parse_ini if lower.endswith(".ini") else
             _parse_calibration_yaml if lower.endswith((".yaml", ".yml")) else None)
    if parse is None:
        return None
    try:
        with open(file_name, encoding="utf-8") as f:
            return parse(f.read())
    except (OSError, UnicodeDecodeError, CameraInfoError, yaml.YAMLError):
        return None
