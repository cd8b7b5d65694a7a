"""Ready-made tasks: event frequency, timestamp delays, heartbeat."""

from __future__ import annotations

import threading
from typing import Any, Dict

import minros

from .status import DiagnosticStatusWrapper
from .updater import DiagnosticTask


class FrequencyStatusParam:
    """Bounds for :class:`FrequencyStatus`: ``freq_bound`` is a dict with 'min' and optionally
    'max' (read on every run, so changing it takes effect); acceptable is
    [min * (1 - tolerance), max * (1 + tolerance)] over the last ``window_size`` runs."""

    def __init__(self, freq_bound: Dict[str, float], tolerance: float = 0.1,
                 window_size: int = 5) -> None:
        self.freq_bound = freq_bound
        self.tolerance = tolerance
        self.window_size = window_size


class FrequencyStatus(DiagnosticTask):
    """Counts :meth:`tick` calls; warns when their rate leaves the bounds, errors on none."""

    def __init__(self, params: FrequencyStatusParam, name: str = "FrequencyStatus") -> None:
        DiagnosticTask.__init__(self, name)
        self.params = params
        self.lock = threading.Lock()
        self.clear()

    def clear(self) -> None:
        with self.lock:
            self.count = 0
            now = minros.Time.now()
            self.times = [now] * self.params.window_size
            self.seq_nums = [0] * self.params.window_size
            self.hist_indx = 0

    def tick(self) -> None:
        with self.lock:
            self.count += 1

    def run(self, stat: DiagnosticStatusWrapper) -> DiagnosticStatusWrapper:
        with self.lock:
            now = minros.Time.now()
            events = self.count - self.seq_nums[self.hist_indx]
            window = (now - self.times[self.hist_indx]).to_sec()
            if window != 0:
                freq = events / window
            else:  # two runs at one instant (paused simulated time): as C++'s double division
                freq = float("nan") if events == 0 else float("inf")
            self.seq_nums[self.hist_indx] = self.count
            self.times[self.hist_indx] = now
            self.hist_indx = (self.hist_indx + 1) % self.params.window_size
            bound = self.params.freq_bound
            tolerance = self.params.tolerance
            if events == 0:
                stat.summary(2, "No events recorded.")
            elif freq < bound["min"] * (1 - tolerance):
                stat.summary(1, "Frequency too low.")
            elif "max" in bound and freq > bound["max"] * (1 + tolerance):
                stat.summary(1, "Frequency too high.")
            else:
                stat.summary(0, "Desired frequency met")
            stat.add("Events in window", f"{events:d}")
            stat.add("Events since startup", f"{self.count:d}")
            stat.add("Duration of window (s)", f"{window:f}")
            stat.add("Actual frequency (Hz)", f"{freq:f}")
            if "max" in bound and bound["min"] == bound["max"]:
                stat.add("Target frequency (Hz)", f"{bound['min']:f}")
            if bound["min"] > 0:
                stat.add("Minimum acceptable frequency (Hz)", f"{bound['min'] * (1 - tolerance):f}")
            if "max" in bound:
                stat.add("Maximum acceptable frequency (Hz)", f"{bound['max'] * (1 + tolerance):f}")
        return stat


class TimeStampStatusParam:
    """Acceptable delays (now - stamp, seconds) for :class:`TimeStampStatus`."""

    def __init__(self, min_acceptable: float = -1, max_acceptable: float = 5) -> None:
        self.max_acceptable = max_acceptable
        self.min_acceptable = min_acceptable


class TimeStampStatus(DiagnosticTask):
    """Checks the delay of ticked timestamps; errors on ones too old, from the future or zero."""

    def __init__(self, params: TimeStampStatusParam | None = None,
                 name: str = "Timestamp Status") -> None:
        DiagnosticTask.__init__(self, name)
        self.params = params if params is not None else TimeStampStatusParam()
        self.lock = threading.Lock()
        self.early_count = 0
        self.late_count = 0
        self.zero_count = 0
        self.zero_seen = False
        self.max_delta = 0
        self.min_delta = 0
        self.deltas_valid = False

    def tick(self, stamp: Any) -> None:
        """Note an event stamped ``stamp`` (seconds as a float, or a Time)."""
        if not isinstance(stamp, float):
            stamp = stamp.to_sec()
        with self.lock:
            if stamp == 0:
                self.zero_seen = True
                return
            delta = minros.Time.now().to_sec() - stamp
            if not self.deltas_valid or delta > self.max_delta:
                self.max_delta = delta
            if not self.deltas_valid or delta < self.min_delta:
                self.min_delta = delta
            self.deltas_valid = True

    def run(self, stat: DiagnosticStatusWrapper) -> DiagnosticStatusWrapper:
        with self.lock:
            stat.summary(0, "Timestamps are reasonable.")
            if not self.deltas_valid:
                stat.summary(1, "No data since last update.")
            else:
                if self.min_delta < self.params.min_acceptable:
                    stat.summary(2, "Timestamps too far in future seen.")
                    self.early_count += 1
                if self.max_delta > self.params.max_acceptable:
                    stat.summary(2, "Timestamps too far in past seen.")
                    self.late_count += 1
                if self.zero_seen:
                    stat.summary(2, "Zero timestamp seen.")
                    self.zero_count += 1
            stat.add("Earliest timestamp delay:", f"{self.min_delta:f}")
            stat.add("Latest timestamp delay:", f"{self.max_delta:f}")
            stat.add("Earliest acceptable timestamp delay:", f"{self.params.min_acceptable:f}")
            stat.add("Latest acceptable timestamp delay:", f"{self.params.max_acceptable:f}")
            stat.add("Late diagnostic update count:", f"{self.late_count:d}")
            stat.add("Early diagnostic update count:", f"{self.early_count:d}")
            stat.add("Zero seen diagnostic update count:", f"{self.zero_count:d}")
            self.deltas_valid = False
            self.min_delta = 0
            self.max_delta = 0
            self.zero_seen = False
        return stat


class Heartbeat(DiagnosticTask):
    """Always OK: "Alive"."""

    def __init__(self) -> None:
        DiagnosticTask.__init__(self, "Heartbeat")

    def run(self, stat: DiagnosticStatusWrapper) -> DiagnosticStatusWrapper:
        stat.summary(0, "Alive")
        return stat
