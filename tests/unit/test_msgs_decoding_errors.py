"""A string field that is not UTF-8: the bytes become U+FFFD and one ERROR is logged per
message type, with genpy's text (its 'rosmsg' error handler), as rospy nodes on Debian log it."""

from __future__ import annotations

import io
import json
import logging
import struct
import subprocess

from support import PYTHON, REFERENCE_PYTHON, reference_env, require_reference

BAD = b"a\xffb\xfe"

#: decodes a KeyValue (whose key is BAD) three times and a DiagnosticStatus whose name is not
#: UTF-8 twice, in a fresh process (the "only once" is per process), printing the values and
#: the 'rosout' logger's records
SCRIPT = r"""
import io, json, logging, struct
records = []
class Keep(logging.Handler):
    def emit(self, record):
        records.append([record.levelname, record.getMessage()])
logging.getLogger('rosout').addHandler(Keep())
from diagnostic_msgs.msg import DiagnosticStatus, KeyValue
def text(data):
    return struct.pack('<I', len(data)) + data
bad = BAD_BYTES
values = [KeyValue().deserialize(text(bad) + text(b'ok')).key for _ in range(3)]
buff = io.BytesIO()
DiagnosticStatus(level=1, name='x', message='m', hardware_id='h').serialize(buff)
raw = buff.getvalue().replace(b'\x01\x00\x00\x00x', b'\x01\x00\x00\x00\xff', 1)
values += [DiagnosticStatus().deserialize(raw).name for _ in range(2)]
print(json.dumps([values, records]))
""".replace("BAD_BYTES", repr(BAD))


def _run(python: str, env=None) -> list:
    out = subprocess.run([python, "-c", SCRIPT], capture_output=True, text=True, timeout=60,
                         env=env)
    assert out.returncode == 0, out.stderr
    return json.loads(out.stdout)


def test_replacement_characters_and_one_error_per_type():
    values, records = _run(PYTHON)
    assert values == ["a\ufffdb\ufffd"] * 3 + ["\ufffd"] * 2
    assert records == [
        ["ERROR", "Characters replaced when decoding message diagnostic_msgs/KeyValue (will "
                  "print only once): 'utf-8' codec can't decode byte 0xff in position 1: "
                  "invalid start byte"],
        ["ERROR", "Characters replaced when decoding message diagnostic_msgs/DiagnosticStatus "
                  "(will print only once): 'utf-8' codec can't decode byte 0xff in position 0: "
                  "invalid start byte"]]


def test_the_same_values_and_lines_as_debians_genpy():
    require_reference()
    assert _run(PYTHON) == _run(REFERENCE_PYTHON, reference_env({}))


def test_a_valid_string_logs_nothing(caplog):
    from std_msgs.msg import String

    caplog.set_level(logging.DEBUG, logger="rosout")
    buff = io.BytesIO()
    String(data="grüß").serialize(buff)
    assert String().deserialize(buff.getvalue()).data == "grüß"
    assert struct.unpack_from("<I", buff.getvalue())[0] == len("grüß".encode())
    assert not caplog.records
