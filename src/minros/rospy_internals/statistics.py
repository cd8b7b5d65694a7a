"""rospy.impl.statistics: topic statistics (/enable_statistics; minros.client.statistics)."""

from minros.client.statistics import ConnectionStatistics as ConnectionStatisticsLogger  # noqa: F401
from minros.client.statistics import SubscriberStatistics as SubscriberStatisticsLogger  # noqa: F401
