"""The genpy stand-in exposes what scripts import from genpy, backed by minros.msgs."""

from __future__ import annotations

import io

import pytest

import genpy
import genpy.dynamic
import genpy.message
from std_msgs.msg import Header, String


def test_time_duration_and_message_base():
    assert genpy.Time(1, 5).to_nsec() == 1_000_000_005
    assert (genpy.Time(2) - genpy.Time(1)) == genpy.Duration(1)
    assert isinstance(String(), genpy.Message)
    assert issubclass(genpy.DeserializationError, genpy.MessageException)


def test_message_lookup_and_dynamic_classes():
    assert genpy.message.get_message_class("std_msgs/Header") is Header
    classes = genpy.dynamic.generate_dynamic("std_msgs/String", String._full_text)
    dynamic = classes["std_msgs/String"]
    buff = io.BytesIO()
    dynamic(data="hi").serialize(buff)
    assert String().deserialize(buff.getvalue()).data == "hi"


def test_truncated_data_raises_genpy_deserialization_error():
    with pytest.raises(genpy.DeserializationError):
        String().deserialize(b"\x05\x00\x00\x00ab")
