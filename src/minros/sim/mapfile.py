"""map_server's map files: a YAML description naming an image, and map_saver's writer.

The YAML keys are map_server's (ros-planning/navigation, noetic-devel, ``map_server/src``):
``image`` (relative to the YAML file's folder), ``resolution`` (m/pixel), ``origin``
``[x, y, yaw]`` of the lower-left pixel, ``negate`` (0/1), ``occupied_thresh``,
``free_thresh`` and the optional ``mode`` (``trinary``, the default, ``scale`` or ``raw``).

A pixel becomes an occupancy value as map_server's image loader computes it: the mean of its
colour channels (alpha included in trinary mode, excluded otherwise), inverted when
``negate`` is 0 (``occ = (255 - mean) / 255``: black is occupied); then ``occ >
occupied_thresh`` -> 100, ``occ < free_thresh`` -> 0, anything between -> -1 (unknown) in
trinary mode, or ``1 + 98 * (occ - free) / (occupied - free)`` (truncated) in scale mode
unless the pixel's "alpha" is 0. In raw mode the value is the mean itself (a byte, so values
above 127 read back negative in the int8 grid, as in ROS). Like map_server, the loader reads a
three-channel pixel's last byte in SDL's memory order (blue) as its alpha; only scale mode
looks at it. Image rows are flipped so that row 0 of the grid is the bottom of the picture.

map_saver writes a PGM (254 free, 0 occupied, 205 unknown, with ``--free``/``--occ`` as
thresholds on the 0..100 values) and a YAML with ``negate: 0``, ``occupied_thresh: 0.65``,
``free_thresh: 0.196``. Unlike ROS's map_saver, the YAML names the image by its file name,
relative to the YAML (map_saver writes the path given to ``-f``, which breaks the pair when
``-f`` names another folder).

Every failure raises :class:`MapError` with one line naming the file and what to fix.
"""

from __future__ import annotations

import math
import os
from dataclasses import dataclass
from typing import Any, Dict, Tuple

import numpy as np

from minros.sim.grid import GridMap

MODES = ("trinary", "scale", "raw")
#: map_saver's defaults, and the thresholds it writes into the YAML
SAVER_OCCUPIED = 65
SAVER_FREE = 25
SAVER_YAML_OCCUPIED = 0.65
SAVER_YAML_FREE = 0.196
#: The largest image minros loads (cells): 16k x 16k, 256 MB of int8 grid.
MAX_CELLS = 1 << 28


class MapError(Exception):
    """A map file could not be used; the message is one line saying why and what to fix."""


@dataclass
class MapDescription:
    """What a map YAML file says (paths resolved)."""

    image: str
    resolution: float
    origin: Tuple[float, float, float]
    negate: bool
    occupied_thresh: float
    free_thresh: float
    mode: str = "trinary"


def _number(doc: Dict[str, Any], key: str, path: str) -> float:
    value = doc.get(key)
    if isinstance(value, bool) or not isinstance(value, (int, float)) or not math.isfinite(value):
        raise MapError(f"{path}: the map does not contain a {key} tag or it is invalid "
                       f"(expected a number, found {value!r})")
    return float(value)


def read_description(path: str) -> MapDescription:
    """Parse and check a map YAML file (map_server's keys and rules)."""
    import yaml

    try:
        with open(path, encoding="utf-8") as f:
            text = f.read(1 << 20)
    except FileNotFoundError:
        raise MapError(f"map file {path} does not exist (give the path of a map .yaml, as "
                       "map_saver writes them)") from None
    except (OSError, UnicodeDecodeError) as exc:
        raise MapError(f"cannot read map file {path}: {getattr(exc, 'strerror', None) or exc}") from None
    try:
        doc = yaml.safe_load(text)
    except yaml.YAMLError as exc:
        mark = getattr(exc, "problem_mark", None)
        where = f" at line {mark.line + 1}" if mark is not None else ""
        problem = getattr(exc, "problem", None) or type(exc).__name__
        raise MapError(f"{path} is not valid YAML{where}: {problem}") from None
    if not isinstance(doc, dict):
        raise MapError(f"{path} is not a map description: expected keys image, resolution, "
                       "origin, negate, occupied_thresh, free_thresh")
    resolution = _number(doc, "resolution", path)
    if resolution <= 0:
        raise MapError(f"{path}: resolution must be positive (metres per pixel), not {resolution}")
    negate = doc.get("negate")
    if isinstance(negate, bool):
        negate = int(negate)
    if not isinstance(negate, int):
        raise MapError(f"{path}: the map does not contain a negate tag or it is invalid "
                       f"(expected 0 or 1, found {negate!r})")
    occ = _number(doc, "occupied_thresh", path)
    free = _number(doc, "free_thresh", path)
    mode = doc.get("mode", "trinary")
    if mode not in MODES:
        raise MapError(f"{path}: invalid mode tag {mode!r} (trinary, scale or raw)")
    if mode == "scale" and not free < occ:
        raise MapError(f"{path}: free_thresh ({free}) must be below occupied_thresh ({occ})")
    origin = doc.get("origin")
    if (not isinstance(origin, (list, tuple)) or len(origin) != 3
            or not all(isinstance(v, (int, float)) and not isinstance(v, bool)
                       and math.isfinite(v) for v in origin)):
        raise MapError(f"{path}: the map does not contain an origin tag or it is invalid "
                       f"(expected [x, y, yaw], found {origin!r})")
    image = doc.get("image")
    if not isinstance(image, str):
        raise MapError(f"{path}: the map does not contain an image tag or it is invalid")
    if not image:
        raise MapError(f"{path}: the image tag cannot be an empty string")
    if not os.path.isabs(image):
        image = os.path.join(os.path.dirname(os.path.abspath(path)), image)
    return MapDescription(image=image, resolution=resolution,
                          origin=(float(origin[0]), float(origin[1]), float(origin[2])),
                          negate=bool(negate), occupied_thresh=occ, free_thresh=free, mode=mode)


def read_image(path: str) -> np.ndarray:
    """The image's pixels: (H, W) gray or (H, W, C) in OpenCV's BGR(A) order, 8 bits."""
    import cv2

    if not os.path.exists(path):
        raise MapError(f'failed to open image file "{path}": no such file')
    if os.path.isdir(path):
        raise MapError(f'failed to open image file "{path}": it is a folder')
    pixels = _quiet_imread(cv2, path)
    if pixels is None or pixels.size == 0:
        raise MapError(f'failed to open image file "{path}": not an image OpenCV can read '
                       "(PGM, PNG, BMP, JPEG, ...) or damaged")
    if pixels.dtype == np.uint16:  # SDL_image hands map_server 8 bits per channel
        pixels = (pixels >> 8).astype(np.uint8)
    elif pixels.dtype != np.uint8:
        raise MapError(f'failed to open image file "{path}": {pixels.dtype} pixels are not supported')
    if pixels.shape[0] * pixels.shape[1] > MAX_CELLS:
        raise MapError(f'image file "{path}" is too large ({pixels.shape[1]} x {pixels.shape[0]})')
    return pixels


def _quiet_imread(cv2: Any, path: str) -> Any:
    """cv2.imread without OpenCV's own log lines on stderr (the MapError says it once)."""
    logging = getattr(getattr(cv2, "utils", None), "logging", None)
    if logging is None:
        return cv2.imread(path, cv2.IMREAD_UNCHANGED)
    level = logging.getLogLevel()
    logging.setLogLevel(logging.LOG_LEVEL_SILENT)
    try:
        return cv2.imread(path, cv2.IMREAD_UNCHANGED)
    finally:
        logging.setLogLevel(level)


def occupancy_from_pixels(pixels: np.ndarray, negate: bool, occupied_thresh: float,
                          free_thresh: float, mode: str = "trinary") -> np.ndarray:
    """map_server's pixel -> occupancy rule for a whole image; rows flipped (row 0 = bottom)."""
    if mode not in MODES:
        raise ValueError(f"mode must be one of {MODES}")
    img = pixels if pixels.ndim == 3 else pixels[:, :, None]
    channels = img.shape[2]
    has_alpha = channels == 4
    averaged = channels if (mode == "trinary" or not has_alpha) else channels - 1
    mean = img[:, :, :averaged].astype(np.float64).sum(axis=2) / averaged
    if channels == 1:
        alpha = np.ones(mean.shape)
    elif channels == 3:
        alpha = img[:, :, 0].astype(np.float64)  # the last byte of an R,G,B pixel in memory
    else:
        alpha = img[:, :, 3].astype(np.float64)
    if negate:
        mean = 255.0 - mean
    if mode == "raw":
        return np.ascontiguousarray(mean.astype(np.uint8)[::-1]).view(np.int8)
    occ = (255.0 - mean) / 255.0
    out = np.full(mean.shape, -1, dtype=np.int16)
    between = ~((occ > occupied_thresh) | (occ < free_thresh))
    if mode == "scale":
        opaque = between & ~(alpha < 1.0)
        ratio = (occ[opaque] - free_thresh) / (occupied_thresh - free_thresh)
        out[opaque] = (1.0 + 98.0 * ratio).astype(np.int16)
    out[occ < free_thresh] = 0
    out[occ > occupied_thresh] = 100
    return np.ascontiguousarray(out[::-1].astype(np.int8))


def load_map(path: str) -> Tuple[GridMap, MapDescription]:
    """Read a map YAML file and its image (map_server's ``map.yaml`` argument)."""
    desc = read_description(path)
    pixels = read_image(desc.image)
    data = occupancy_from_pixels(pixels, desc.negate, desc.occupied_thresh, desc.free_thresh,
                                 desc.mode)
    return GridMap(data, desc.resolution, desc.origin), desc


def load_image_map(image: str, resolution: float, negate: bool = False,
                   occupied_thresh: float = 0.65, free_thresh: float = 0.196) -> GridMap:
    """map_server's deprecated ``map_server IMAGE RESOLUTION`` form: trinary, origin 0."""
    if not (math.isfinite(resolution) and resolution > 0):
        raise MapError(f"resolution must be a positive number of metres per pixel, not {resolution}")
    pixels = read_image(image)
    return GridMap(occupancy_from_pixels(pixels, negate, occupied_thresh, free_thresh),
                   resolution, (0.0, 0.0, 0.0))


# -- map_saver -------------------------------------------------------------------------------


def saver_pixels(data: np.ndarray, occupied: int = SAVER_OCCUPIED,
                 free: int = SAVER_FREE) -> np.ndarray:
    """map_saver's picture of a grid: 254 for 0..free, 0 for >= occupied, 205 otherwise;
    rows flipped back (the picture's top row is the grid's last)."""
    values = np.asarray(data, dtype=np.int16)
    out = np.full(values.shape, 205, dtype=np.uint8)
    out[values >= occupied] = 0
    out[(values >= 0) & (values <= free)] = 254
    return np.ascontiguousarray(out[::-1])


def check_saver_thresholds(occupied: int, free: int) -> None:
    """map_saver's argument rules, as MapError."""
    if not 1 <= occupied <= 100:
        raise MapError("threshold_occupied must be between 1 and 100")
    if not 0 <= free <= 100:
        raise MapError("threshold_free must be between 0 and 100")
    if occupied <= free:
        raise MapError("threshold_free must be smaller than threshold_occupied")


def pgm_bytes(pixels: np.ndarray, resolution: float) -> bytes:
    """A binary PGM (P5) of 8-bit ``pixels`` with map_saver's comment line."""
    height, width = pixels.shape
    header = (f"P5\n# CREATOR: minros map_saver {resolution:.3f} m/pix\n"
              f"{width} {height}\n255\n").encode("ascii")
    return header + np.ascontiguousarray(pixels, dtype=np.uint8).tobytes()


def saver_yaml(image_name: str, resolution: float, origin: Tuple[float, float, float]) -> str:
    """The YAML map_saver writes (its printf formats), naming ``image_name``."""
    x, y, yaw = origin
    return (f"image: {image_name}\nresolution: {resolution:f}\n"
            f"origin: [{x:f}, {y:f}, {yaw:f}]\nnegate: 0\n"
            f"occupied_thresh: {SAVER_YAML_OCCUPIED}\nfree_thresh: {SAVER_YAML_FREE}\n\n")


def save_map(grid: GridMap, name: str, occupied: int = SAVER_OCCUPIED,
             free: int = SAVER_FREE) -> Tuple[str, str]:
    """Write ``name.pgm`` and ``name.yaml`` (map_saver ``-f name``); returns both paths."""
    check_saver_thresholds(occupied, free)
    pgm, yml = name + ".pgm", name + ".yaml"
    try:
        _write_atomic(pgm, pgm_bytes(saver_pixels(grid.data, occupied, free), grid.resolution))
        _write_atomic(yml, saver_yaml(os.path.basename(pgm), grid.resolution,
                                      grid.origin).encode("utf-8"))
    except OSError as exc:
        raise MapError(f"couldn't save map file to {pgm}: {exc.strerror or exc}") from None
    return pgm, yml


def _write_atomic(path: str, data: bytes) -> None:
    tmp = f"{path}.tmp{os.getpid()}"
    try:
        with open(tmp, "wb") as f:
            f.write(data)
        os.replace(tmp, path)
    finally:
        if os.path.exists(tmp):
            os.unlink(tmp)
