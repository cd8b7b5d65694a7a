"""Property tests over every bundled message type: round trips, truncation, random bytes."""

from __future__ import annotations

import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from minros.exceptions import DeserializationError
from minros.msgs import get_message_class, reader_for
from minros.msgs.testing import bundled_types, strategy_for

TYPES = bundled_types()
FAST = settings(max_examples=6, deadline=None, database=None,
                suppress_health_check=list(HealthCheck))
#: The properties over every type are one test function per 400 types: a parametrized
#: hypothesis test of more than about 950 cases ends in a RecursionError inside hypothesis
#: itself (seen with hypothesis 6.140-6.170 on pytest 8 and 9: a bare test of 952 integer cases
#: is enough; two functions of 600 are not), and the bundled types passed 950 with ros_control's.
CHUNK = 400


def _per_chunk(name: str, body, *decorators) -> None:
    """Define ``name_0``, ``name_1``, ... in this module, each ``body`` over CHUNK types."""
    for n, start in enumerate(range(0, len(TYPES), CHUNK)):
        test = given(data=st.data())(body)
        for decorate in decorators:
            test = decorate(test)
        test = pytest.mark.parametrize("type_name", TYPES[start:start + CHUNK])(test)
        globals()[f"{name}_{n}"] = test


def test_every_package_has_types() -> None:
    packages = {t.split("/")[0] for t in TYPES}
    assert {"std_msgs", "geometry_msgs", "sensor_msgs", "rosgraph_msgs", "std_srvs",
            "turtlesim", "rospy_tutorials", "nav_msgs", "visualization_msgs"} <= packages
    assert len(TYPES) > 170


def _round_trip_and_truncation(type_name: str, data) -> None:
    cls = get_message_class(type_name)
    msg = data.draw(strategy_for(type_name))
    wire = msg.serialize_to_bytes()
    back = cls().deserialize(wire)
    assert back == msg
    assert back.serialize_to_bytes() == wire
    # the receivers' reader (new objects, no default fields built first) agrees, from bytes
    # and from a bytearray as a subscriber's buffer hands it over
    read = reader_for(cls)
    for given_wire in (wire, bytearray(wire)):
        fresh = read(given_wire)
        assert type(fresh) is cls
        assert fresh == msg
        assert fresh.serialize_to_bytes() == wire
    if wire:
        cut = data.draw(st.integers(0, len(wire) - 1))
        with pytest.raises(DeserializationError):
            cls().deserialize(wire[:cut])
        with pytest.raises(DeserializationError):
            read(wire[:cut])
    with pytest.raises(DeserializationError):
        cls().deserialize(wire + b"\x00")
    with pytest.raises(DeserializationError):
        read(wire + b"\x00")


_per_chunk("test_round_trip_and_truncation", _round_trip_and_truncation, FAST)


@pytest.mark.parametrize("type_name", [
    "std_msgs/String", "std_msgs/Header", "sensor_msgs/PointCloud2", "sensor_msgs/Image",
    "visualization_msgs/InteractiveMarkerUpdate", "rosgraph_msgs/Log", "nav_msgs/Path",
    "diagnostic_msgs/DiagnosticArray", "trajectory_msgs/JointTrajectory", "std_msgs/Float64MultiArray",
])
@settings(max_examples=60, deadline=None, database=None)
@given(blob=st.binary(max_size=96))
def test_random_bytes_only_raise_deserialization_error(type_name: str, blob: bytes) -> None:
    cls = get_message_class(type_name)
    try:
        fresh = reader_for(cls)(blob)
    except DeserializationError:
        fresh = None
    try:
        msg = cls().deserialize(blob)
    except DeserializationError:
        assert fresh is None  # both readers refuse the same bytes
        return
    # accepted: every field was filled (bools/time may be normalised, so no byte equality)
    assert all(hasattr(msg, name) for name in cls.__slots__)
    assert fresh == msg


def test_reader_for_keeps_an_overridden_deserialize() -> None:
    """A subclass with its own deserialize (as numpy_msg variants and hand-written classes
    have) is read through it, never around it."""
    from minros.msgs import numpy_msg

    String = get_message_class("std_msgs/String")

    class Shouting(String):
        __slots__ = ()

        def deserialize(self, data):
            super().deserialize(data)
            self.data = self.data.upper()
            return self

    assert reader_for(Shouting)(String("hi").serialize_to_bytes()).data == "HI"
    Floats = numpy_msg(get_message_class("std_msgs/Float32MultiArray"))
    wire = get_message_class("std_msgs/Float32MultiArray")(data=[1.0, 2.5]).serialize_to_bytes()
    got = reader_for(Floats)(wire)
    assert type(got) is Floats and got.data.tolist() == [1.0, 2.5]  # a numpy array, as rospy's


def _dynamic_classes_from_full_text_agree(type_name: str, data) -> None:
    """What rostopic echo and bag tools rebuild from message_definition reads the same bytes."""
    from minros.msgs import generate_dynamic

    cls = get_message_class(type_name)
    dynamic = generate_dynamic(type_name, cls._full_text)[type_name]
    assert dynamic._md5sum == cls._md5sum and dynamic._full_text == cls._full_text
    wire = data.draw(strategy_for(type_name)).serialize_to_bytes()
    assert dynamic().deserialize(wire).serialize_to_bytes() == wire


_per_chunk("test_dynamic_classes_from_full_text_agree", _dynamic_classes_from_full_text_agree,
           settings(max_examples=2, deadline=None, database=None,
                    suppress_health_check=list(HealthCheck)))
