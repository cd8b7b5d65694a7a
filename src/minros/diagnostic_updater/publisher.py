"""Diagnostics of a topic: publication frequency and, with headers, timestamp delays."""

from __future__ import annotations

from typing import Any

from .functions import FrequencyStatus, FrequencyStatusParam, TimeStampStatus, TimeStampStatusParam
from .updater import CompositeDiagnosticTask, Updater


class HeaderlessTopicDiagnostic(CompositeDiagnosticTask):
    """"<name> topic status": the frequency of :meth:`tick` calls; adds itself to ``diag``."""

    def __init__(self, name: str, diag: Updater, freq: FrequencyStatusParam) -> None:
        CompositeDiagnosticTask.__init__(self, name + " topic status")
        self.diag = diag
        self.freq = FrequencyStatus(freq)
        self.addTask(self.freq)
        self.diag.add(self)

    def tick(self) -> None:
        self.freq.tick()

    def clear_window(self) -> None:
        self.freq.clear()


class TopicDiagnostic(HeaderlessTopicDiagnostic):
    """Frequency and timestamp delay of a topic's messages."""

    def __init__(self, name: str, diag: Updater, freq: FrequencyStatusParam,
                 stamp: TimeStampStatusParam) -> None:
        HeaderlessTopicDiagnostic.__init__(self, name, diag, freq)
        self.stamp = TimeStampStatus(stamp)
        self.addTask(self.stamp)

    def tick(self, stamp: Any) -> None:  # type: ignore[override]
        self.stamp.tick(stamp)
        HeaderlessTopicDiagnostic.tick(self)


class DiagnosedPublisher(TopicDiagnostic):
    """A Publisher whose :meth:`publish` also ticks the topic's diagnostics."""

    def __init__(self, pub: Any, diag: Updater, freq: FrequencyStatusParam,
                 stamp: TimeStampStatusParam) -> None:
        TopicDiagnostic.__init__(self, pub.name, diag, freq, stamp)
        self.publisher = pub

    def publish(self, message: Any) -> None:
        self.tick(message.header.stamp)
        self.publisher.publish(message)
