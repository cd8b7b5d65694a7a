"""rospy.impl.statistics: topic statistics (minros.rospy_internals.statistics)."""

from minros.rospy_internals.statistics import (  # noqa: F401
    ConnectionStatisticsLogger,
    SubscriberStatisticsLogger,
)
