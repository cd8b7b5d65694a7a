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

Every failure raises :class:`MapError` with one line naming the file and what to fix. An
image's size is read from its header (:func:`image_header`: PNG's IHDR, the PNM/PAM header,
JPEG's SOF, BMP's, TIFF's first IFD, WebP's, GIF's, Sun raster's) before anything is decoded,
so that a small file claiming a huge picture costs nothing; a format whose header minros does
not read is refused rather than handed to the decoder blind. The grid is converted in bands of
rows, so that the float temporaries stay small next to the decoded picture.
"""

from __future__ import annotations

import math
import os
import struct
from dataclasses import dataclass
from typing import Any, BinaryIO, Dict, Tuple

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
#: The most the decoded picture may take (bytes): 16k x 16k RGBA, or 8k x 8k at 16 bits.
MAX_IMAGE_BYTES = 1 << 30
#: what the header readers accept, for the error that names them
IMAGE_FORMATS = "PGM/PPM/PBM/PAM, PNG, JPEG, BMP, TIFF, WebP, GIF or Sun raster"
#: rows converted at a time (bounds the float temporaries of occupancy_from_pixels)
_BAND_CELLS = 1 << 20


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


def _finite(value: Any) -> bool:
    """A finite int or float (not a bool; an int too large for a float is not finite)."""
    if isinstance(value, bool) or not isinstance(value, (int, float)):
        return False
    try:
        return math.isfinite(value)
    except OverflowError:
        return False


def _shown(value: Any) -> str:
    """``repr(value)``, cut short (an error names what it found, not all of it)."""
    try:
        text = repr(value)
    except ValueError:  # an int beyond the interpreter's digit limit
        return "a huge number"
    return text if len(text) <= 60 else text[:57] + "..."


def _number(doc: Dict[str, Any], key: str, path: str) -> float:
    value = doc.get(key)
    if not _finite(value):
        raise MapError(f"{path}: the map does not contain a {key} tag or it is invalid "
                       f"(expected a number, found {_shown(value)})")
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
    except (OSError, UnicodeDecodeError, ValueError) as exc:  # ValueError: a NUL in the path
        raise MapError(f"cannot read map file {path}: {getattr(exc, 'strerror', None) or exc}") from None
    try:
        doc = yaml.safe_load(text)
    except RecursionError:  # PyYAML composes nested collections recursively
        raise MapError(f"{path} is not a map description: its YAML nests too deeply (a map "
                       "file is one level of keys)") from None
    except yaml.YAMLError as exc:
        mark = getattr(exc, "problem_mark", None)
        where = f" at line {mark.line + 1}" if mark is not None else ""
        problem = getattr(exc, "problem", None) or type(exc).__name__
        raise MapError(f"{path} is not valid YAML{where}: {problem}") from None
    except (ValueError, TypeError, OverflowError) as exc:  # a scalar PyYAML cannot construct
        problem = str(exc).splitlines()[0][:120] if str(exc) else type(exc).__name__
        raise MapError(f"{path} is not valid YAML: {problem}") from None
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
                       f"(expected 0 or 1, found {_shown(negate)})")
    occ = _number(doc, "occupied_thresh", path)
    free = _number(doc, "free_thresh", path)
    mode = doc.get("mode", "trinary")
    if mode not in MODES:
        raise MapError(f"{path}: invalid mode tag {_shown(mode)} (trinary, scale or raw)")
    if mode == "scale" and not free < occ:
        raise MapError(f"{path}: free_thresh ({free}) must be below occupied_thresh ({occ})")
    origin = doc.get("origin")
    if (not isinstance(origin, (list, tuple)) or len(origin) != 3
            or not all(_finite(v) for v in origin)):
        raise MapError(f"{path}: the map does not contain an origin tag or it is invalid "
                       f"(expected [x, y, yaw], found {_shown(origin)})")
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


@dataclass
class ImageHeader:
    """What an image's header says: its size and, where the header tells, the bytes a decoded
    pixel takes (otherwise the most the format's decoder produces)."""

    format: str
    width: int
    height: int
    pixel_bytes: int = 4


def _damaged(what: str) -> ValueError:
    return ValueError(f"its {what} header is damaged")


def _pnm_header(f: BinaryIO, magic: bytes) -> ImageHeader:
    """P1..P6 (width, height[, maxval]: tokens separated by white space and # comments), P7
    (PAM: WIDTH/HEIGHT/DEPTH/MAXVAL lines up to ENDHDR)."""
    head = f.read(4096)
    if magic == b"P7":
        fields: Dict[str, int] = {}
        for line in head[2:].split(b"\n"):
            words = line.split(b"#")[0].split()
            if words == [b"ENDHDR"]:
                break
            if len(words) == 2 and words[1].isdigit():
                fields[words[0].decode("ascii", "replace")] = int(words[1])
        if "WIDTH" not in fields or "HEIGHT" not in fields:
            raise _damaged("PAM")
        sample = 2 if fields.get("MAXVAL", 255) > 255 else 1
        return ImageHeader("PAM", fields["WIDTH"], fields["HEIGHT"],
                           max(1, min(4, fields.get("DEPTH", 1))) * sample)
    tokens = []
    i = 2
    wanted = 2 if magic in (b"P1", b"P4") else 3
    while len(tokens) < wanted and i < len(head):
        c = head[i:i + 1]
        if c == b"#":
            end = head.find(b"\n", i)
            i = len(head) if end < 0 else end + 1
        elif c.isspace():
            i += 1
        else:
            j = i
            while j < len(head) and head[j:j + 1].isdigit():
                j += 1
            if j == i:
                raise _damaged("PNM")
            tokens.append(int(head[i:j]))
            i = j
    if len(tokens) < wanted:
        raise _damaged("PNM")
    channels = 3 if magic in (b"P3", b"P6") else 1
    sample = 2 if wanted == 3 and tokens[2] > 255 else 1
    return ImageHeader("PNM", tokens[0], tokens[1], channels * sample)


def _jpeg_header(f: BinaryIO) -> ImageHeader:
    """The first start-of-frame segment (SOF0..SOF15 but DHT, JPG and DAC) after the SOI."""
    f.seek(2)
    while True:
        byte = f.read(1)
        while byte == b"\xff":  # fill bytes before a marker
            byte = f.read(1)
        if not byte:
            raise _damaged("JPEG")
        marker = byte[0]
        if marker == 0x01 or 0xD0 <= marker <= 0xD9:
            continue  # standalone markers: no length
        raw = f.read(2)
        if len(raw) < 2:
            raise _damaged("JPEG")
        (length,) = struct.unpack(">H", raw)
        if length < 2:
            raise _damaged("JPEG")
        if 0xC0 <= marker <= 0xCF and marker not in (0xC4, 0xC8, 0xCC):
            body = f.read(6)
            if len(body) < 6:
                raise _damaged("JPEG")
            _precision, height, width, components = struct.unpack(">BHHB", body)
            if height == 0:  # the height comes later, in a DNL segment: not worth following
                raise _damaged("JPEG")
            return ImageHeader("JPEG", width, height, 1 if components == 1 else 3)
        f.seek(length - 2, os.SEEK_CUR)
        if marker == 0xDA:  # start of scan before any frame
            raise _damaged("JPEG")


def _tiff_header(f: BinaryIO, order: str) -> ImageHeader:
    """ImageWidth (256), ImageLength (257), BitsPerSample (258) and SamplesPerPixel (277)
    from the first IFD (classic TIFF; BigTIFF is refused)."""
    f.seek(4)
    (offset,) = struct.unpack(order + "I", f.read(4))
    f.seek(offset)
    raw = f.read(2)
    if len(raw) < 2:
        raise _damaged("TIFF")
    (count,) = struct.unpack(order + "H", raw)
    entries = f.read(12 * count)
    values: Dict[int, int] = {}
    for k in range(len(entries) // 12):
        tag, kind, _n = struct.unpack(order + "HHI", entries[12 * k:12 * k + 8])
        if tag in (256, 257, 258, 277):
            if kind == 3:
                (values[tag],) = struct.unpack(order + "H", entries[12 * k + 8:12 * k + 10])
            elif kind == 4:
                (values[tag],) = struct.unpack(order + "I", entries[12 * k + 8:12 * k + 12])
    if 256 not in values or 257 not in values:
        raise _damaged("TIFF")
    samples = max(1, min(4, values.get(277, 1)))
    sample = 2 if values.get(258, 8) > 8 else 1  # the decoder widens 1..7 bits to 8
    return ImageHeader("TIFF", values[256], values[257], samples * sample)


def _webp_header(head: bytes) -> ImageHeader:
    chunk = head[12:16]
    if chunk == b"VP8 " and head[23:26] == b"\x9d\x01\x2a":
        width, height = struct.unpack("<HH", head[26:30])
        return ImageHeader("WebP", width & 0x3FFF, height & 0x3FFF, 4)
    if chunk == b"VP8L" and head[20:21] == b"\x2f":
        (bits,) = struct.unpack("<I", head[21:25])
        return ImageHeader("WebP", (bits & 0x3FFF) + 1, ((bits >> 14) & 0x3FFF) + 1, 4)
    if chunk == b"VP8X" and len(head) >= 30:
        width = int.from_bytes(head[24:27], "little") + 1
        height = int.from_bytes(head[27:30], "little") + 1
        return ImageHeader("WebP", width, height, 4)
    raise _damaged("WebP")


def image_header(path: str) -> ImageHeader:
    """The size of the image at ``path`` from its header, without decoding it. Raises
    ValueError (saying what is wrong) for a format not listed in IMAGE_FORMATS or a
    damaged header; OSError when the file cannot be read."""
    with open(path, "rb") as f:
        head = f.read(64)
        try:
            if head.startswith(b"\x89PNG\r\n\x1a\n"):
                if head[12:16] != b"IHDR":
                    raise _damaged("PNG")
                width, height, depth, colour = struct.unpack(">IIBB", head[16:26])
                channels = {0: 1, 2: 3, 3: 4, 4: 2, 6: 4}.get(colour, 4)
                return ImageHeader("PNG", width, height, channels * (2 if depth > 8 else 1))
            if len(head) >= 2 and head[:1] == b"P" and head[1:2] in b"1234567":
                f.seek(0)
                return _pnm_header(f, head[:2])
            if head.startswith(b"\xff\xd8"):
                return _jpeg_header(f)
            if head.startswith(b"BM") and len(head) >= 26:
                (dib,) = struct.unpack("<I", head[14:18])
                if dib == 12:
                    width, height = struct.unpack("<HH", head[18:22])
                else:
                    width, height = struct.unpack("<ii", head[18:26])
                return ImageHeader("BMP", abs(width), abs(height), 4)
            if head[:4] in (b"II*\x00", b"MM\x00*"):
                return _tiff_header(f, "<" if head[:2] == b"II" else ">")
            if head[:4] == b"RIFF" and head[8:12] == b"WEBP":
                return _webp_header(head)
            if head[:6] in (b"GIF87a", b"GIF89a"):
                width, height = struct.unpack("<HH", head[6:10])
                return ImageHeader("GIF", width, height, 4)
            if head.startswith(b"\x59\xa6\x6a\x95"):
                width, height, depth = struct.unpack(">III", head[4:16])
                return ImageHeader("Sun raster", width, height, 1 if depth <= 8 else 4)
        except (struct.error, OverflowError) as exc:
            raise ValueError("its header is damaged") from exc
    raise ValueError(f"not an image format map_server reads here ({IMAGE_FORMATS})")


def read_image(path: str) -> np.ndarray:
    """The image's pixels: (H, W) gray or (H, W, C) in OpenCV's BGR(A) order, 8 bits.

    The header is checked first: no more than MAX_CELLS pixels and MAX_IMAGE_BYTES decoded."""
    import cv2

    if not os.path.exists(path):
        raise MapError(f'failed to open image file "{path}": no such file')
    if os.path.isdir(path):
        raise MapError(f'failed to open image file "{path}": it is a folder')
    try:
        header = image_header(path)
    except OSError as exc:
        raise MapError(f'failed to open image file "{path}": {exc.strerror or exc}') from None
    except ValueError as exc:
        raise MapError(f'failed to open image file "{path}": not an image OpenCV can read '
                       f"(PGM, PNG, BMP, JPEG, ...) or damaged: {exc}") from None
    if header.width <= 0 or header.height <= 0:
        raise MapError(f'failed to open image file "{path}": its {header.format} header says '
                       f"{header.width} x {header.height} pixels")
    cells = header.width * header.height
    if cells > MAX_CELLS or cells * header.pixel_bytes > MAX_IMAGE_BYTES:
        raise MapError(f'image file "{path}" is too large ({header.width} x {header.height} '
                       f"{header.format}, at most {MAX_CELLS} pixels and "
                       f"{MAX_IMAGE_BYTES >> 20} MB decoded): scale it down and raise the "
                       "resolution in the YAML to match")
    try:
        pixels = _quiet_imread(cv2, path)
    except cv2.error as exc:
        reason = str(exc).strip().splitlines()[-1] if str(exc).strip() else "cv2.error"
        raise MapError(f'failed to open image file "{path}": the decoder failed ({reason})') from None
    if pixels is None or pixels.size == 0:
        raise MapError(f'failed to open image file "{path}": not an image OpenCV can read '
                       "(PGM, PNG, BMP, JPEG, ...) or damaged")
    if pixels.dtype == np.uint16:  # SDL_image hands map_server 8 bits per channel
        np.right_shift(pixels, 8, out=pixels)
        pixels = pixels.astype(np.uint8)
    elif pixels.dtype != np.uint8:
        raise MapError(f'failed to open image file "{path}": {pixels.dtype} pixels are not supported')
    if pixels.shape[0] * pixels.shape[1] > MAX_CELLS:  # a header that undercounted
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
    height = pixels.shape[0]
    width = max(1, pixels.shape[1]) if pixels.ndim >= 2 else 1
    out = np.empty(pixels.shape[:2], dtype=np.int8)
    band = max(1, _BAND_CELLS // width)
    for top in range(0, height, band):
        rows = _occupancy_band(pixels[top:top + band], negate, occupied_thresh, free_thresh,
                               mode)
        # picture rows top..top+n become grid rows height-top-n..height-top, flipped
        out[height - top - rows.shape[0]:height - top] = rows[::-1]
    return out


def _occupancy_band(pixels: np.ndarray, negate: bool, occupied_thresh: float,
                    free_thresh: float, mode: str) -> np.ndarray:
    """occupancy_from_pixels for a band of picture rows, in picture order (not flipped)."""
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
        return mean.astype(np.uint8).view(np.int8)
    occ = (255.0 - mean) / 255.0
    out = np.full(mean.shape, -1, dtype=np.int16)
    between = ~((occ > occupied_thresh) | (occ < free_thresh))
    if mode == "scale":
        opaque = between & ~(alpha < 1.0)
        ratio = (occ[opaque] - free_thresh) / (occupied_thresh - free_thresh)
        out[opaque] = (1.0 + 98.0 * ratio).astype(np.int16)
    out[occ < free_thresh] = 0
    out[occ > occupied_thresh] = 100
    return out.astype(np.int8)


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
