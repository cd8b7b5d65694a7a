"""roslz4 (minros.roslz4) against Debian's roslz4 (a C extension): the same frames, each
reading the other's."""

from __future__ import annotations

import os
import subprocess

import pytest

import roslz4
from support import REFERENCE_PYTHON, reference_env, reference_imports, require_reference

pytestmark = pytest.mark.interop

SAMPLES = [b"", b"x", b"hello world" * 100, bytes(range(256)) * 4000,
           os.urandom(1 << 20) + b"tail" * 70000]

RUN = r'''
import sys, roslz4
data = sys.stdin.buffer.read()
op = sys.argv[1]
sys.stdout.buffer.write(roslz4.compress(data) if op == "c" else roslz4.decompress(data))
'''


def debian(op: str, data: bytes) -> bytes:
    out = subprocess.run([REFERENCE_PYTHON, "-c", RUN, op], input=data, capture_output=True,
                         env=reference_env({}), timeout=120)
    assert out.returncode == 0, out.stderr.decode()
    return out.stdout


@pytest.mark.parametrize("index", range(len(SAMPLES)))
def test_frames_equal_and_cross_read(index: int):
    require_reference()
    if not reference_imports("roslz4"):
        pytest.skip("Debian's python3-roslz4 is not installed")
    data = SAMPLES[index]
    ours, theirs = roslz4.compress(data), debian("c", data)
    assert roslz4.decompress(theirs) == data
    assert debian("d", ours) == data
    if len(data) < (1 << 20):  # one block: the same compressor settings give the same bytes
        assert ours == theirs
