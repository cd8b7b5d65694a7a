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


def test_a_png_beyond_opencvs_own_limit_is_one_line(tmp_path):
    path = write_map(tmp_path, np.zeros((1, 1), np.uint8), name="vast", image="vast.png")
    (tmp_path / "vast.png").write_bytes(png_bytes(60000, 60000, rows=10))
    with pytest.raises(mapfile.MapError) as info:
        mapfile.load_map(str(path))
    assert "is too large (60000 x 60000 PNG" in str(info.value) and "\n" not in str(info.value)


@pytest.mark.parametrize("text, expected", [
    ("image: m.png\nresolution: " + "[" * 10_000 + "]" * 10_000 + "\n", "nests too deeply"),
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
