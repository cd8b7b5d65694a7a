"""diagnostic_updater for minros: collect a node's health and publish it on /diagnostics.

The ``diagnostic_updater`` stand-in re-exports this package; names, texts and levels are those
of ROS 1's python3-diagnostic-updater (1.11), so aggregators and rqt_robot_monitor read a
minros node's diagnostics as any other's.
"""

from diagnostic_msgs.msg import DiagnosticArray, DiagnosticStatus, KeyValue

from .functions import (
    FrequencyStatus,
    FrequencyStatusParam,
    Heartbeat,
    TimeStampStatus,
    TimeStampStatusParam,
)
from .publisher import DiagnosedPublisher, HeaderlessTopicDiagnostic, TopicDiagnostic
from .status import ERROR, OK, WARN, DiagnosticStatusWrapper
from .updater import (
    CompositeDiagnosticTask,
    DiagnosticTask,
    DiagnosticTaskVector,
    FunctionDiagnosticTask,
    Updater,
)

__all__ = [
    "OK", "WARN", "ERROR", "DiagnosticStatusWrapper", "DiagnosticTask", "FunctionDiagnosticTask",
    "CompositeDiagnosticTask", "DiagnosticTaskVector", "Updater", "FrequencyStatusParam",
    "FrequencyStatus", "TimeStampStatusParam", "TimeStampStatus", "Heartbeat",
    "HeaderlessTopicDiagnostic", "TopicDiagnostic", "DiagnosedPublisher",
    # ROS's modules star-import these messages, so `from diagnostic_updater import *` gives them
    "DiagnosticArray", "DiagnosticStatus", "KeyValue",
]
