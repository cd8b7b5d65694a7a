"""Time and Duration follow genpy's semantics."""

from __future__ import annotations

import pickle

import pytest

from minros.msgs import Duration, Time


def test_canonical_form_and_float_constructor() -> None:
    assert (Time(1, 1500000000).secs, Time(1, 1500000000).nsecs) == (2, 500000000)
    d = Duration(0, -1)
    assert (d.secs, d.nsecs) == (-1, 999999999)
    assert Time(1.5) == Time(1, 500000000)
    assert Time.from_sec(2.25).to_nsec() == 2250000000
    assert Duration.from_sec(-0.5) == Duration(0, -500000000)
    with pytest.raises(ValueError):
        Time(1.5, 3)
    with pytest.raises(TypeError):
        Time(-1)


def test_arithmetic_and_types() -> None:
    t = Time(10, 0) + Duration(1, 500000000)
    assert isinstance(t, Time) and t == Time(11, 500000000)
    assert isinstance(Time(5) - Time(3), Duration) and Time(5) - Time(3) == Duration(2)
    assert isinstance(Time(5) - Duration(3), Time)
    assert Duration(1) * 3 == Duration(3) and 2 * Duration(1) == Duration(2)
    assert Duration(3) / 2 == Duration(1, 500000000) and Duration(3) / Duration(2) == 1.5
    assert Duration(7) // Duration(2) == 3 and Duration(7) % Duration(2) == Duration(1)
    assert -Duration(1, 5) == Duration(-1, -5) and abs(Duration(-2)) == Duration(2)
    with pytest.raises(TypeError):
        Time(1) + Time(1)


def test_comparisons_hash_bool_str() -> None:
    assert Time(1) < Time(2) and Duration(-1) < Duration(0)
    assert Time(1) != Duration(1) and not (Time(1) == Duration(1))
    with pytest.raises(TypeError):
        Time(1) < Duration(2)  # noqa: B015
    assert hash(Time(1, 2)) == hash(Time(1, 2)) and len({Time(1), Time(1)}) == 1
    assert not Time() and Time(0, 1) and Time().is_zero()
    assert str(Time(1, 5)) == "1000000005" and repr(Duration(2)) == "genpy.Duration[2000000000]"
    assert Time(3, 4).to_sec() == 3.000000004
    assert pickle.loads(pickle.dumps(Time(3, 4))) == Time(3, 4)
