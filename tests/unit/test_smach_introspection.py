"""smach introspection's userdata codec: ROS's encoding out, only plain values in."""

from __future__ import annotations

import base64
import os
import pickle

import pytest

from minros.smach_ros.introspection import decode_userdata, encode_userdata


class Evil:
    def __reduce__(self):
        return (os.system, ("true",))


def test_encoding_is_base64_of_a_protocol_2_pickle() -> None:
    text = encode_userdata({"a": 1, "b": [1.5, "x"], "c": b"\x00\xff"})
    assert pickle.loads(base64.b64decode(text)) == {"a": 1, "b": [1.5, "x"], "c": b"\x00\xff"}
    assert base64.b64decode(text)[:2] == b"\x80\x02"


def test_unpicklable_values_are_left_out() -> None:
    text = encode_userdata({"ok": 1, "lock": __import__("threading").Lock()})
    assert pickle.loads(base64.b64decode(text)) == {"ok": 1}


@pytest.mark.parametrize("value", [{"a": 1}, {"s": {1, 2}, "t": (1, "x"), "b": b"\x01"}, {}])
def test_plain_values_round_trip(value) -> None:
    assert decode_userdata(encode_userdata(value).encode()) == value
    assert decode_userdata(pickle.dumps(value, 2)) == value  # raw pickle bytes (ROS 2's smach)


@pytest.mark.parametrize("payload, message", [
    (base64.b64encode(pickle.dumps({"x": Evil()}, 2)), "refusing to build"),
    (base64.b64encode(pickle.dumps([1, 2], 2)), "must be a pickled dict"),
    (b"not a pickle at all", "not a pickle of plain values"),
    (b"A" * (3 << 20), "over the"),
])
def test_bad_userdata_is_refused_with_a_reason(payload: bytes, message: str) -> None:
    with pytest.raises(ValueError, match=message):
        decode_userdata(payload)
