"""map_server's map format in minros.sim.mapfile: pixel rules, YAML checks, map_saver's files.

The expected values follow map_server's image loader (ros-planning/navigation noetic-devel,
map_server/src/image_loader.cpp); the spectrum counts are those its own unit test asserts for
its 16 x 16 image of every gray level (map_server/test/utest.cpp, testMapMode), against which
this loader was also checked on the upstream test images themselves."""

from __future__ import annotations

import os
from pathlib import Path

import cv2
import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from minros.sim import mapfile
from minros.sim.grid import GridMap

SPECTRUM = np.arange(256, dtype=np.uint8).reshape(16, 16)


def write_map(folder: Path, pixels: np.ndarray, name: str = "m", image: str | None = None,
              **keys) -> Path:
    image = image or f"{name}.png"
    cv2.imwrite(str(folder / image), pixels)
    doc = {"image": image, "resolution": 0.05, "origin": "[1.0, -2.0, 0.0]", "negate": 0,
           "occupied_thresh": 0.65, "free_thresh": 0.196}
    doc.update(keys)
    text = "".join(f"{k}: {v}\n" for k, v in doc.items() if v is not None)
    path = folder / f"{name}.yaml"
    path.write_text(text)
    return path


def counts(data: np.ndarray) -> dict:
    values, numbers = np.unique(data.view(np.uint8), return_counts=True)
    return dict(zip(values.tolist(), numbers.tolist()))


def test_spectrum_counts_as_map_servers_own_test():
    trinary = counts(mapfile.occupancy_from_pixels(SPECTRUM, False, 0.65, 0.1, "trinary"))
    assert (trinary[100], trinary[0], trinary[255]) == (90, 26, 140)
    scale = counts(mapfile.occupancy_from_pixels(SPECTRUM, False, 0.65, 0.1, "scale"))
    assert (scale[100], scale[0]) == (90, 26)
    assert sum(n for v, n in scale.items() if 0 < v < 100) == 140
    raw = counts(mapfile.occupancy_from_pixels(SPECTRUM, False, 0.65, 0.1, "raw"))
    assert len(raw) == 256 and set(raw.values()) == {1}


def test_pixel_values_thresholds_and_negate():
    px = np.array([[0, 254, 205, 128, 100]], dtype=np.uint8)
    out = mapfile.occupancy_from_pixels(px, False, 0.65, 0.196)
    # 205 -> occ 0.19608 is not below 0.196: unknown, as map_saver's 205 is meant to be
    assert out.tolist() == [[100, 0, -1, -1, -1]]
    assert mapfile.occupancy_from_pixels(px, True, 0.65, 0.196).tolist() == [[0, 100, 100, -1, -1]]
    # scale: 1 + 98 * (occ - free) / (occ_th - free), truncated
    scale = mapfile.occupancy_from_pixels(np.array([[128]], np.uint8), False, 0.65, 0.196, "scale")
    occ = (255 - 128) / 255.0
    assert scale[0, 0] == int(1 + 98 * (occ - 0.196) / (0.65 - 0.196)) == 66
    # raw: the mean as a byte, which the int8 grid reads back negative above 127
    raw = mapfile.occupancy_from_pixels(np.array([[200, 7]], np.uint8), False, 0.65, 0.196, "raw")
    assert raw.tolist() == [[-56, 7]]


def test_rows_are_flipped_so_row_zero_is_the_bottom():
    px = np.full((3, 2), 254, np.uint8)
    px[0, 0] = 0  # top-left pixel
    out = mapfile.occupancy_from_pixels(px, False, 0.65, 0.196)
    assert out[2, 0] == 100 and out[0, 0] == 0


def test_colour_and_alpha_channels():
    # RGB: the mean of the three channels
    bgr = np.zeros((1, 1, 3), np.uint8)
    bgr[0, 0] = (255, 255, 0)  # mean 170
    assert mapfile.occupancy_from_pixels(bgr, False, 0.65, 0.196).tolist() == [[-1]]
    # RGBA: trinary mode averages alpha in with the colours; scale mode leaves it out of the
    # mean and makes a transparent pixel between the thresholds unknown
    bgra = np.array([[(0, 0, 0, 255), (128, 128, 128, 0), (128, 128, 128, 255),
                      (255, 255, 255, 0)]], np.uint8)
    trinary = mapfile.occupancy_from_pixels(bgra, False, 0.65, 0.196, "trinary")
    assert trinary.tolist() == [[100, -1, -1, -1]]  # white + alpha 0: mean 191 -> occ 0.25
    scale = mapfile.occupancy_from_pixels(bgra, False, 0.65, 0.196, "scale")
    assert scale.tolist() == [[100, -1, 66, 0]]


def test_load_map_reads_yaml_and_image_relative_to_the_yaml(tmp_path):
    px = np.full((4, 6), 254, np.uint8)
    px[:, 0] = 0
    path = write_map(tmp_path, px)
    grid, desc = mapfile.load_map(str(path))
    assert (grid.width, grid.height, grid.resolution, grid.origin) == (6, 4, 0.05, (1.0, -2.0, 0.0))
    assert desc.image == str(tmp_path / "m.png") and desc.mode == "trinary"
    assert (grid.data[:, 0] == 100).all() and (grid.data[:, 1:] == 0).all()


@pytest.mark.parametrize("keys, expected", [
    ({"resolution": None}, "resolution tag"),
    ({"resolution": "fast"}, "resolution tag"),
    ({"resolution": -1}, "resolution must be positive"),
    ({"negate": None}, "negate tag"),
    ({"occupied_thresh": None}, "occupied_thresh tag"),
    ({"free_thresh": "x"}, "free_thresh tag"),
    ({"origin": "[1, 2]"}, "origin tag"),
    ({"origin": None}, "origin tag"),
    ({"mode": "fancy"}, "invalid mode tag 'fancy'"),
    ({"image": '""'}, "image tag cannot be an empty string"),
    ({"image": "missing.png"}, 'failed to open image file'),
])
def test_bad_yaml_gets_one_line_naming_the_key(tmp_path, keys, expected):
    px = np.full((2, 2), 254, np.uint8)
    image = keys.pop("image", None)
    path = write_map(tmp_path, px, **keys)
    if image is not None:
        text = path.read_text().replace("image: m.png", f"image: {image}")
        path.write_text(text)
    with pytest.raises(mapfile.MapError) as info:
        mapfile.load_map(str(path))
    assert expected in str(info.value)
    assert "\n" not in str(info.value)


def test_missing_garbled_and_non_yaml_files(tmp_path):
    with pytest.raises(mapfile.MapError, match="does not exist"):
        mapfile.load_map(str(tmp_path / "nope.yaml"))
    (tmp_path / "broken.yaml").write_text("image: [unclosed\nresolution: 0.05\n")
    with pytest.raises(mapfile.MapError, match="is not valid YAML at line"):
        mapfile.load_map(str(tmp_path / "broken.yaml"))
    (tmp_path / "list.yaml").write_text("- 1\n- 2\n")
    with pytest.raises(mapfile.MapError, match="not a map description"):
        mapfile.load_map(str(tmp_path / "list.yaml"))
    path = write_map(tmp_path, np.zeros((2, 2), np.uint8), name="garbled")
    (tmp_path / "garbled.png").write_bytes(b"\x89PNG\r\n\x1a\n" + os.urandom(300))
    with pytest.raises(mapfile.MapError, match="not an image OpenCV can read"):
        mapfile.load_map(str(path))


def test_map_saver_files_round_trip_through_map_server(tmp_path):
    data = np.array([[0, 100, -1], [30, 70, 0]], dtype=np.int8)
    grid = GridMap(data, 0.05, (-1.5, 2.0, 0.25))
    pgm, yml = mapfile.save_map(grid, str(tmp_path / "saved"))
    text = Path(yml).read_text()
    assert text == ("image: saved.pgm\nresolution: 0.050000\norigin: [-1.500000, 2.000000, "
                    "0.250000]\nnegate: 0\noccupied_thresh: 0.65\nfree_thresh: 0.196\n\n")
    raw = Path(pgm).read_bytes()
    assert raw.startswith(b"P5\n# CREATOR: minros map_saver 0.050 m/pix\n3 2\n255\n")
    # the picture's top row is the grid's last: [30 -> unknown, 70 -> occupied, 0 -> free]
    assert list(raw[-6:]) == [205, 0, 254, 254, 0, 205]
    loaded, _ = mapfile.load_map(yml)
    assert loaded.data.tolist() == [[0, 100, -1], [-1, 100, 0]]
    assert loaded.origin == (-1.5, 2.0, 0.25) and loaded.resolution == 0.05


def test_map_saver_thresholds():
    data = np.array([[10, 20, 50]], dtype=np.int8)
    assert mapfile.saver_pixels(data, occupied=50, free=10).tolist() == [[254, 205, 0]]
    for occ, free, text in ((0, 25, "threshold_occupied must be between 1 and 100"),
                            (65, 101, "threshold_free must be between 0 and 100"),
                            (30, 30, "threshold_free must be smaller than threshold_occupied")):
        with pytest.raises(mapfile.MapError, match=text):
            mapfile.check_saver_thresholds(occ, free)


def test_the_default_world_is_a_valid_map():
    from minros.sim.world import DEFAULT_WORLD

    grid, desc = mapfile.load_map(DEFAULT_WORLD)
    assert (grid.width, grid.height, grid.resolution) == (200, 160, 0.05)
    assert set(np.unique(grid.data).tolist()) == {0, 100}


@settings(max_examples=150, deadline=None)
@given(text=st.text(max_size=300), image=st.binary(max_size=200))
def test_any_yaml_or_image_file_loads_or_is_one_map_error(tmp_path_factory, text, image):
    folder = tmp_path_factory.mktemp("fuzz")
    (folder / "m.png").write_bytes(image)
    (folder / "m.yaml").write_text(text)
    for path in (folder / "m.yaml", folder / "good.yaml"):
        if path.name == "good.yaml":  # a valid description naming the random image
            path.write_text("image: m.png\nresolution: 0.05\norigin: [0, 0, 0]\nnegate: 0\n"
                            "occupied_thresh: 0.65\nfree_thresh: 0.196\n")
        try:
            grid, _ = mapfile.load_map(str(path))
        except mapfile.MapError as exc:
            assert "\n" not in str(exc)
        else:
            assert grid.data.dtype == np.int8 and grid.data.ndim == 2


# -- hostile map files: the size is read from the header, every failure is one line ----------


def png_bytes(width: int, height: int, rows: int | None = None, colour: int = 0) -> bytes:
    """A gray 8-bit PNG of ``width`` x ``height`` zeros (``rows`` of them compressed: fewer
    makes a truncated file whose header still claims the whole size)."""
    import struct
    import zlib

    def chunk(kind: bytes, body: bytes) -> bytes:
        return (struct.pack(">I", len(body)) + kind + body
                + struct.pack(">I", zlib.crc32(kind + body)))

    channels = {0: 1, 2: 3, 6: 4}[colour]
    compressor = zlib.compressobj(9)
    row = bytes(1 + width * channels)
    parts = []
    left = height if rows is None else rows
    while left > 0:
        n = min(left, 100)
        parts.append(compressor.compress(row * n))
        left -= n
    parts.append(compressor.flush())
    ihdr = struct.pack(">IIBBBBB", width, height, 8, colour, 0, 0, 0)
    return (b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", ihdr) + chunk(b"IDAT", b"".join(parts))
            + chunk(b"IEND", b""))


@pytest.mark.slow
def test_a_small_png_claiming_a_huge_picture_costs_no_memory(tmp_path):
    """An attacker's 400 kB PNG of 20000 x 20000 zeros: refused from its header (it used to be
    decoded first, 400 MB, then refused)."""
    import subprocess
    import sys

    image = tmp_path / "huge.png"
    path = write_map(tmp_path, np.zeros((1, 1), np.uint8), name="huge", image="huge.png")
    image.write_bytes(png_bytes(20000, 20000))  # write_map wrote a 1 x 1 image over it
    assert image.stat().st_size < 1_000_000
    probe = ("import resource, sys\n"
             "from minros.sim import mapfile\n"
             "import cv2, numpy\n"
             "before = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss\n"
             "try:\n"
             "    mapfile.load_map(sys.argv[1])\n"
             "except mapfile.MapError as exc:\n"
             "    print(exc)\n"
             "print(resource.getrusage(resource.RUSAGE_SELF).ru_maxrss - before)\n")
    out = subprocess.run([sys.executable, "-c", probe, str(path)], capture_output=True,
                         text=True, timeout=60)
    assert out.returncode == 0, out.stderr
    message, grown_kb = out.stdout.strip().splitlines()
    assert int(grown_kb) < 20_000, f"loading grew the peak RSS by {int(grown_kb) >> 10} MB"
    assert "is too large (20000 x 20000 PNG" in message and "scale it down" in message
    assert out.stderr == ""


def png_zeros(width: int, height: int, colour: int = 6) -> bytes:
    """A complete 8-bit PNG of ``width`` x ``height`` zeros, built fast: one deflate block of
    rows ended by a full flush (so that it stands alone) repeated, and the Adler-32 of all."""
    import struct
    import zlib

    def chunk(kind: bytes, body: bytes) -> bytes:
        return (struct.pack(">I", len(body)) + kind + body
                + struct.pack(">I", zlib.crc32(kind + body)))

    row = bytes(1 + width * {0: 1, 2: 3, 4: 2, 6: 4}[colour])
    per = max(1, (1 << 22) // len(row))
    whole, rest = divmod(height, per)
    raw = zlib.compressobj(9, zlib.DEFLATED, -15)
    block = raw.compress(row * per) + raw.flush(zlib.Z_FULL_FLUSH)
    tail = zlib.compressobj(9, zlib.DEFLATED, -15)
    last = tail.compress(row * rest) + tail.flush()
    check = 1
    for _ in range(whole):
        check = zlib.adler32(row * per, check)
    check = zlib.adler32(row * rest, check)
    data = b"\x78\xda" + block * whole + last + struct.pack(">I", check)
    ihdr = struct.pack(">IIBBBBB", width, height, 8, colour, 0, 0, 0)
    return (b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", ihdr) + chunk(b"IDAT", data)
            + chunk(b"IEND", b""))


#: loads a map in a fresh process and prints the MapError (or "loaded") and the growth of the
#: peak RSS in bytes, measured after a first small decode (OpenCV's codecs are loaded lazily)
PEAK_PROBE = (
    "import os, resource, sys, tempfile\n"
    "import cv2, numpy\n"
    "from minros.sim import mapfile\n"
    "warm = os.path.join(tempfile.mkdtemp(), 'w.png')\n"
    "cv2.imwrite(warm, numpy.zeros((4, 4, 4), numpy.uint8)); cv2.imread(warm, -1)\n"
    "before = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss\n"
    "try:\n"
    "    mapfile.load_map(sys.argv[1])\n"
    "    print('loaded')\n"
    "except mapfile.MapError as exc:\n"
    "    print(exc)\n"
    "print((resource.getrusage(resource.RUSAGE_SELF).ru_maxrss - before) * 1024)\n")


def _load_in_a_process(path: Path) -> tuple:
    import subprocess
    import sys

    out = subprocess.run([sys.executable, "-c", PEAK_PROBE, str(path)], capture_output=True,
                         text=True, timeout=120)
    assert out.returncode == 0 and out.stderr == "", out.stderr
    message, grown = out.stdout.strip().splitlines()
    return message, int(grown)


@pytest.mark.slow
def test_a_1mb_png_of_16384_square_rgba_is_refused_from_its_header(tmp_path):
    """1 GiB decoded passed the old limit (MAX_CELLS and 1 GiB): map_server spent 2.1 GB and
    34 s on it. A map needs what its grid needs as 8-bit gray: 256 MiB decoded."""
    path = write_map(tmp_path, np.zeros((1, 1), np.uint8), name="rgba", image="rgba.png")
    (tmp_path / "rgba.png").write_bytes(png_zeros(16384, 16384, colour=6))
    assert (tmp_path / "rgba.png").stat().st_size < 1_100_000
    message, grown = _load_in_a_process(path)
    assert "is too large (16384 x 16384 PNG" in message and "256 MB decoded" in message
    assert grown < 20 << 20, f"refusing it grew the peak RSS by {grown >> 20} MB"


def test_the_load_peak_is_bounded_for_any_accepted_file():
    """What the README says: at most 2 x 256 MiB + 32 MiB, whatever the file."""
    assert mapfile.MAX_IMAGE_BYTES == 256 << 20
    assert 2 * mapfile.MAX_IMAGE_BYTES + mapfile.LOAD_SCRATCH == 544 << 20
    for width, height, pixel_bytes in [(16384, 16384, 1), (8192, 8192, 4), (1 << 28, 1, 1),
                                       (8192, 4096, 8)]:
        header = mapfile.ImageHeader("PNG", width, height, pixel_bytes)
        assert width * height <= mapfile.MAX_CELLS
        assert width * height * pixel_bytes <= mapfile.MAX_IMAGE_BYTES
        assert mapfile.load_peak_bytes(header) <= 544 << 20


@pytest.mark.slow
@pytest.mark.parametrize("shape, dtype, mode, image", [
    ((3000, 3000), np.uint8, "trinary", "m.png"),
    ((2000, 2000, 4), np.uint8, "trinary", "m.png"),
    ((2000, 2000, 3), np.uint8, "scale", "m.png"),
    ((1500, 1500, 4), np.uint16, "scale", "m.png"),
    ((16, 1 << 20), np.uint8, "raw", "m.pgm"),  # OpenCV's widest: bands cut in columns
])
def test_loading_peaks_within_load_peak_bytes(tmp_path, shape, dtype, mode, image):
    """The peak RSS a load adds, measured, is within ``load_peak_bytes`` of the header (which
    the limits keep under 544 MB): twice the decoded picture (OpenCV's buffer and numpy's copy)
    and the scratch; the grid and the bands fit in the copy's place."""
    rng = np.random.default_rng(3)
    pixels = rng.integers(0, np.iinfo(dtype).max, shape, dtype=dtype)
    path = write_map(tmp_path, pixels, mode=mode, image=image)
    header = mapfile.image_header(str(tmp_path / image))
    assert header.pixel_bytes == pixels.itemsize * (1 if pixels.ndim == 2 else shape[2])
    message, grown = _load_in_a_process(path)
    assert message == "loaded"
    assert grown <= mapfile.load_peak_bytes(header), (
        f"grew {grown >> 20} MB, the bound is {mapfile.load_peak_bytes(header) >> 20} MB")


def test_png_headers_count_what_opencv_decodes(tmp_path):
    """Gray + alpha decodes as BGRA, RGB with a tRNS chunk as BGRA: the header says so (it said
    2 and 3 bytes a pixel, so a picture could decode to twice what the limit allowed)."""
    import struct
    import zlib

    def chunk(kind: bytes, body: bytes) -> bytes:
        return (struct.pack(">I", len(body)) + kind + body
                + struct.pack(">I", zlib.crc32(kind + body)))

    def png(colour: int, per_pixel: int, extra: bytes = b"") -> bytes:
        ihdr = struct.pack(">IIBBBBB", 5, 3, 8, colour, 0, 0, 0)
        return (b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", ihdr) + extra
                + chunk(b"IDAT", zlib.compress(bytes(1 + 5 * per_pixel) * 3)) + chunk(b"IEND", b""))

    cases = {"gray-alpha": png(4, 2), "rgb-trns": png(2, 3, chunk(b"tRNS", bytes(6))),
             "rgb": png(2, 3), "gray-trns": png(0, 1, chunk(b"tRNS", bytes(2))),
             "palette-trns": png(3, 1, chunk(b"PLTE", bytes(6)) + chunk(b"tRNS", b"\x00"))}
    for name, data in cases.items():
        path = tmp_path / f"{name}.png"
        path.write_bytes(data)
        decoded = cv2.imread(str(path), cv2.IMREAD_UNCHANGED)
        assert decoded is not None, name
        per_pixel = decoded.nbytes // (5 * 3)
        assert mapfile.image_header(str(path)).pixel_bytes == per_pixel, name


def test_a_png_beyond_opencvs_own_limit_is_one_line(tmp_path):
    path = write_map(tmp_path, np.zeros((1, 1), np.uint8), name="vast", image="vast.png")
    (tmp_path / "vast.png").write_bytes(png_bytes(60000, 60000, rows=10))
    with pytest.raises(mapfile.MapError) as info:
        mapfile.load_map(str(path))
    assert "is too large (60000 x 60000 PNG" in str(info.value) and "\n" not in str(info.value)


@pytest.mark.parametrize("text, expected", [
    # a CPU-second of its own (YAML reads the 10,000 brackets first): the slow tier
    pytest.param("image: m.png\nresolution: " + "[" * 10_000 + "]" * 10_000 + "\n",
                 "nests too deeply", marks=pytest.mark.slow),
    ("image: m.png\nresolution: " + "{a: " * 3000 + "1" + "}" * 3000 + "\n", "nests too deeply"),
    ("image: m.png\nresolution: " + "9" * 5000 + "\n", "is not valid YAML: Exceeds the limit"),
    ("image: m.png\nresolution: 1" + "0" * 400 + "\n", "resolution tag or it is invalid"),
    ("image: m.png\nresolution: !!timestamp 2001-13-45\n", "is not valid YAML: month"),
    ("origin: [0, 0, 1" + "0" * 400 + "]\n", "origin tag or it is invalid"),
])
def test_hostile_yaml_is_one_line(tmp_path, text, expected):
    base = ("image: m.png\nresolution: 0.05\norigin: [0, 0, 0]\nnegate: 0\n"
            "occupied_thresh: 0.65\nfree_thresh: 0.196\n")
    keys = {line.split(":")[0] for line in text.splitlines()}
    kept = "".join(line + "\n" for line in base.splitlines() if line.split(":")[0] not in keys)
    (tmp_path / "m.yaml").write_text(kept + text)
    with pytest.raises(mapfile.MapError) as info:
        mapfile.load_map(str(tmp_path / "m.yaml"))
    assert expected in str(info.value) and "\n" not in str(info.value)
    assert len(str(info.value)) < 400


def _small(format_suffix: str, folder: Path) -> Path:
    shape = (3, 5, 3) if format_suffix in (".ppm", ".webp") else (3, 5)
    path = folder / f"small{format_suffix}"
    assert cv2.imwrite(str(path), np.full(shape, 200, np.uint8))
    return path


@pytest.mark.parametrize("suffix, name", [
    (".png", "PNG"), (".pgm", "PNM"), (".ppm", "PNM"), (".pbm", "PNM"), (".pam", "PAM"),
    (".jpg", "JPEG"), (".bmp", "BMP"), (".tif", "TIFF"), (".webp", "WebP"),
    (".ras", "Sun raster")])
def test_image_headers_give_the_size_opencv_decodes(tmp_path, suffix, name):
    path = _small(suffix, tmp_path)
    header = mapfile.image_header(str(path))
    assert (header.format, header.width, header.height) == (name, 5, 3)
    assert mapfile.read_image(str(path)).shape[:2] == (3, 5)


def _forged(kind: str) -> bytes:
    """A few bytes whose header claims 40000 x 40000 pixels."""
    import struct

    n = 40000
    if kind == "png":
        return png_bytes(n, n, rows=1)
    if kind == "pgm":
        return b"P5\n# a comment\n%d %d\n255\n" % (n, n) + bytes(100)
    if kind == "pam":
        return b"P7\nWIDTH %d\nHEIGHT %d\nDEPTH 1\nMAXVAL 255\nENDHDR\n" % (n, n) + bytes(100)
    if kind == "jpeg":
        app0 = b"\xff\xe0" + struct.pack(">H", 16) + b"JFIF\x00\x01\x01\x00\x00\x01\x00\x01\x00\x00"
        sof = b"\xff\xc0" + struct.pack(">HBHHB", 11, 8, n, n, 1) + b"\x01\x11\x00"
        return b"\xff\xd8" + app0 + sof + bytes(100)
    if kind == "bmp":
        return b"BM" + struct.pack("<IHHI", 54, 0, 0, 54) + struct.pack("<IiiHH", 40, n, -n, 1, 8) + bytes(100)
    if kind == "tiff":
        entries = struct.pack("<HHII", 256, 4, 1, n) + struct.pack("<HHII", 257, 4, 1, n)
        return b"II*\x00" + struct.pack("<I", 8) + struct.pack("<H", 2) + entries + bytes(100)
    if kind == "webp":
        body = b"VP8X" + struct.pack("<I", 10) + bytes(4) + (n - 1).to_bytes(3, "little") * 2
        return b"RIFF" + struct.pack("<I", 4 + len(body)) + b"WEBP" + body
    if kind == "gif":
        return b"GIF89a" + struct.pack("<HH", n, n) + bytes(100)
    assert kind == "ras"
    return b"\x59\xa6\x6a\x95" + struct.pack(">IIII", n, n, 8, 0) + bytes(100)


@pytest.mark.parametrize("kind", ["png", "pgm", "pam", "jpeg", "bmp", "tiff", "webp", "gif", "ras"])
def test_forged_headers_are_refused_before_decoding(tmp_path, monkeypatch, kind):
    (tmp_path / "forged.img").write_bytes(_forged(kind))

    def no_decoding(*_args):
        raise AssertionError("the image was handed to the decoder")

    monkeypatch.setattr(mapfile, "_quiet_imread", no_decoding)
    with pytest.raises(mapfile.MapError) as info:
        mapfile.read_image(str(tmp_path / "forged.img"))
    assert "is too large (40000 x 40000" in str(info.value) and "\n" not in str(info.value)


def test_formats_without_a_header_reader_are_refused(tmp_path):
    path = tmp_path / "x.hdr"
    assert cv2.imwrite(str(path), np.zeros((3, 5, 3), np.float32))
    with pytest.raises(mapfile.MapError, match="not an image format map_server reads here"):
        mapfile.read_image(str(path))


def test_banded_conversion_matches_the_whole_image(monkeypatch):
    rng = np.random.default_rng(5)
    pixels = rng.integers(0, 256, (37, 11, 4), dtype=np.uint8)
    whole = {m: mapfile.occupancy_from_pixels(pixels, False, 0.65, 0.196, m) for m in mapfile.MODES}
    monkeypatch.setattr(mapfile, "_BAND_CELLS", 30)  # bands of 2 rows, the last one of 1
    for mode in mapfile.MODES:
        assert np.array_equal(mapfile.occupancy_from_pixels(pixels, False, 0.65, 0.196, mode),
                              whole[mode])
    assert np.array_equal(whole["trinary"][0], mapfile.occupancy_from_pixels(
        pixels[-1:], False, 0.65, 0.196)[0])  # row 0 of the grid is the picture's last


def test_map_server_says_a_huge_map_in_one_line(tmp_path, capsys):
    from minros.nodes.map_server import map_server

    path = write_map(tmp_path, np.zeros((1, 1), np.uint8), name="vast", image="vast.png")
    (tmp_path / "vast.png").write_bytes(png_bytes(60000, 60000, rows=10))
    assert map_server.main(["map_server", str(path)]) == 1
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and err.startswith("map_server: image file ")


def _alias_nest(levels: int = 8, width: int = 10) -> str:
    """YAML's billion laughs: ``levels`` lists of ``width`` aliases of the one below, about
    500 bytes that load (by reference) in milliseconds and stand for width**levels items."""
    lines = ["n0: &n0 [" + ", ".join(["lol"] * width) + "]"]
    lines += [f"n{i}: &n{i} [" + ", ".join([f"*n{i - 1}"] * width) + "]"
              for i in range(1, levels + 1)]
    return "\n".join(lines) + "\n"


@pytest.mark.slow
@pytest.mark.parametrize("key", ["origin", "negate", "resolution", "mode", "occupied_thresh"])
def test_a_nest_of_yaml_aliases_is_one_line_in_bounded_time_and_memory(tmp_path, key):
    """An attacker's 569-byte map YAML whose ``origin`` (or any key an error names) is a nest
    of aliases, 8 levels of 10: its repr is ~10**9 items (map_server hung, 1.46 GB in 30 s)."""
    import subprocess
    import sys
    import time

    base = {"image": "m.png", "resolution": "0.05", "origin": "[0, 0, 0]", "negate": "0",
            "occupied_thresh": "0.65", "free_thresh": "0.196"}
    base[key] = f"*n{8}"
    path = tmp_path / "laughs.yaml"
    path.write_text(_alias_nest() + "".join(f"{k}: {v}\n" for k, v in base.items()))
    assert path.stat().st_size < 700
    probe = ("import resource, sys\n"
             "from minros.nodes.map_server import map_server\n"
             "before = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss\n"
             "code = map_server.main(['map_server', sys.argv[1]])\n"
             "grown = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss - before\n"
             "print(code, grown)\n")
    start = time.monotonic()
    try:
        out = subprocess.run([sys.executable, "-c", probe, str(path)], capture_output=True,
                             text=True, timeout=30)
    except subprocess.TimeoutExpired:
        pytest.fail("map_server did not answer a 600-byte YAML within 30 s")
    elapsed = time.monotonic() - start
    code, grown_kb = out.stdout.split()
    assert code == "1", out.stderr
    assert int(grown_kb) < 20_000, f"the YAML grew the peak RSS by {int(grown_kb) >> 10} MB"
    assert out.stderr.count("\n") == 1 and out.stderr.startswith("map_server: ")
    assert f"{key} tag" in out.stderr and len(out.stderr) < 400
    assert elapsed < 20
