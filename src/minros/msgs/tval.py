"""``Time`` and ``Duration``: the ROS ``time``/``duration`` primitives with genpy's semantics.

Both hold integer ``secs`` and ``nsecs`` in canonical form (0 <= nsecs < 1e9, the sign lives
in ``secs``). ``Time`` is a point (never negative), ``Duration`` a signed span. Arithmetic,
comparisons, hashing and the ``to_sec``/``from_sec``/``to_nsec`` family behave as genpy's
(rospy.Time/Duration subclass these).
"""

from __future__ import annotations

import numbers
from typing import Tuple, TypeVar

_NSEC_PER_SEC = 1000000000
T = TypeVar("T", bound="TVal")


def _canon(secs: int, nsecs: int) -> Tuple[int, int]:
    carry = nsecs // _NSEC_PER_SEC
    return secs + carry, nsecs - carry * _NSEC_PER_SEC


class TVal:
    """Common base of :class:`Time` and :class:`Duration` (secs + nanoseconds)."""

    __slots__ = ("secs", "nsecs")
    # lets message introspection (genpy-style) treat a time value like a message
    _slot_types = ["int32", "int32"]

    def __init__(self, secs: float = 0, nsecs: int = 0) -> None:
        if secs.__class__ is int and nsecs.__class__ is int and 0 <= nsecs < _NSEC_PER_SEC:
            # fast path (every message constructor makes a few): already canonical ints
            self.secs = secs
            self.nsecs = nsecs
            return
        if not isinstance(secs, numbers.Integral):
            if nsecs != 0:
                raise ValueError("if secs is a float, nsecs cannot be set")
            float_secs = secs
            secs = int(float_secs)
            nsecs = int((float_secs - secs) * _NSEC_PER_SEC)
        else:
            secs = int(secs)
            nsecs = int(nsecs)
        self.secs, self.nsecs = _canon(secs, nsecs)

    @classmethod
    def from_sec(cls: type[T], float_secs: float) -> T:
        """A value from float seconds (``time.time()`` style)."""
        secs = int(float_secs)
        nsecs = int((float_secs - secs) * _NSEC_PER_SEC)
        return cls(secs, nsecs)

    def is_zero(self) -> bool:
        return self.secs == 0 and self.nsecs == 0

    def set(self, secs: int, nsecs: int) -> None:
        """Set both fields as given (no canonicalisation, as genpy)."""
        self.secs = secs
        self.nsecs = nsecs

    def canon(self) -> None:
        """Bring ``nsecs`` back into [0, 1e9) after setting the fields by hand."""
        self.secs, self.nsecs = _canon(self.secs, self.nsecs)

    def to_sec(self) -> float:
        return float(self.secs) + float(self.nsecs) / 1e9

    def to_nsec(self) -> int:
        return self.secs * _NSEC_PER_SEC + self.nsecs

    def __hash__(self) -> int:
        return hash((self.secs, self.nsecs))

    def __str__(self) -> str:
        return str(self.to_nsec())

    def __repr__(self) -> str:
        return f"genpy.TVal[{self.to_nsec()}]"

    def __bool__(self) -> bool:
        return self.secs != 0 or self.nsecs != 0

    def _cmp(self, other: object) -> int:
        if not isinstance(other, TVal):
            raise TypeError("cannot compare to non-TVal")
        a, b = self.to_nsec(), other.to_nsec()
        return (a > b) - (a < b)

    def __lt__(self, other: object) -> bool:
        try:
            return self._cmp(other) < 0
        except TypeError:
            return NotImplemented

    def __le__(self, other: object) -> bool:
        try:
            return self._cmp(other) <= 0
        except TypeError:
            return NotImplemented

    def __gt__(self, other: object) -> bool:
        try:
            return self._cmp(other) > 0
        except TypeError:
            return NotImplemented

    def __ge__(self, other: object) -> bool:
        try:
            return self._cmp(other) >= 0
        except TypeError:
            return NotImplemented

    def __eq__(self, other: object) -> bool:
        if not isinstance(other, TVal):
            return False
        return self.to_nsec() == other.to_nsec()

    def __ne__(self, other: object) -> bool:
        return not self.__eq__(other)

    def __getstate__(self) -> list:
        return [self.secs, self.nsecs]

    def __setstate__(self, state: list) -> None:
        self.secs, self.nsecs = state


class Time(TVal):
    """A point in time: seconds and nanoseconds since the epoch (never negative)."""

    __slots__ = ()

    def __init__(self, secs: float = 0, nsecs: int = 0) -> None:
        TVal.__init__(self, secs, nsecs)
        if self.secs < 0:
            raise TypeError("time values must be positive")

    def to_time(self) -> float:
        """Alias of :meth:`to_sec`."""
        return self.to_sec()

    def __hash__(self) -> int:
        return hash((self.secs, self.nsecs))

    def __repr__(self) -> str:
        return f"genpy.Time[{self.to_nsec()}]"

    def __add__(self, other: object):
        if not isinstance(other, Duration):
            return NotImplemented
        return self.__class__(self.secs + other.secs, self.nsecs + other.nsecs)

    __radd__ = __add__

    def __sub__(self, other: object):
        if isinstance(other, Time):
            return Duration(self.secs - other.secs, self.nsecs - other.nsecs)
        if isinstance(other, Duration):
            return self.__class__(self.secs - other.secs, self.nsecs - other.nsecs)
        return NotImplemented

    def _cmp(self, other: object) -> int:
        if not isinstance(other, Time):
            raise TypeError("cannot compare to non-Time")
        return super()._cmp(other)

    def __eq__(self, other: object) -> bool:
        if not isinstance(other, Time):
            return False
        return self.secs == other.secs and self.nsecs == other.nsecs


class Duration(TVal):
    """A signed span of time in seconds and nanoseconds."""

    __slots__ = ()

    def __hash__(self) -> int:
        return hash((self.secs, self.nsecs))

    def __repr__(self) -> str:
        return f"genpy.Duration[{self.to_nsec()}]"

    def __neg__(self):
        return self.__class__(-self.secs, -self.nsecs)

    def __abs__(self):
        return self if self.secs >= 0 else self.__neg__()

    def __add__(self, other: object):
        if isinstance(other, Duration):
            return self.__class__(self.secs + other.secs, self.nsecs + other.nsecs)
        return NotImplemented

    __radd__ = __add__

    def __sub__(self, other: object):
        if not isinstance(other, Duration):
            return NotImplemented
        return self.__class__(self.secs - other.secs, self.nsecs - other.nsecs)

    def __mul__(self, val: object):
        if isinstance(val, numbers.Integral):
            return self.__class__(self.secs * int(val), self.nsecs * int(val))
        if isinstance(val, numbers.Real):
            return self.__class__.from_sec(self.to_sec() * float(val))
        return NotImplemented

    __rmul__ = __mul__

    def __floordiv__(self, val: object):
        if isinstance(val, numbers.Real):
            return self.__class__.from_sec(self.to_sec() // float(val))
        if isinstance(val, Duration):
            return int(self.to_sec() // val.to_sec())
        return NotImplemented

    def __truediv__(self, val: object):
        if isinstance(val, numbers.Real):
            return self.__class__.from_sec(self.to_sec() / float(val))
        if isinstance(val, Duration):
            return self.to_sec() / val.to_sec()
        return NotImplemented

    def __mod__(self, val: object):
        if isinstance(val, Duration):
            return self.__class__.from_sec(self.to_sec() % val.to_sec())
        return NotImplemented

    def __divmod__(self, val: object):
        if isinstance(val, Duration):
            quotient, remainder = divmod(self.to_sec(), val.to_sec())
            return int(quotient), self.__class__.from_sec(remainder)
        return NotImplemented

    def _cmp(self, other: object) -> int:
        if not isinstance(other, Duration):
            raise TypeError("cannot compare to non-Duration")
        return super()._cmp(other)

    def __eq__(self, other: object) -> bool:
        if not isinstance(other, Duration):
            return False
        return self.secs == other.secs and self.nsecs == other.nsecs


# genpy's Time and Duration list their fields in ``__slots__`` and code written for genpy
# iterates them (YAML/JSON converters); here the slots live on TVal, so the subclasses name
# them as a plain class attribute after creation (it no longer affects the layout).
Time.__slots__ = Duration.__slots__ = ["secs", "nsecs"]  # type: ignore[assignment]
