"""message_filters stand-in: message filters and time synchronizers (minros.message_filters)."""

from minros.message_filters import (  # noqa: F401
    ApproximateTimeSynchronizer,
    Cache,
    SimpleFilter,
    Subscriber,
    TimeSynchronizer,
)
