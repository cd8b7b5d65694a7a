"""Diagnostic tasks and the Updater that runs them and publishes on /diagnostics."""

from __future__ import annotations

import http.client
import threading
from typing import Any, Callable, List

import minros
from diagnostic_msgs.msg import DiagnosticArray

from .status import DiagnosticStatusWrapper


class DiagnosticTask:
    """Something that fills a DiagnosticStatusWrapper when run; has a name."""

    def __init__(self, name: str) -> None:
        self.name = name

    def getName(self) -> str:
        return self.name

    def run(self, stat: DiagnosticStatusWrapper) -> DiagnosticStatusWrapper:
        return stat


class FunctionDiagnosticTask(DiagnosticTask):
    """A task whose work is the function ``fn(stat) -> stat``."""

    def __init__(self, name: str, fn: Callable) -> None:
        DiagnosticTask.__init__(self, name)
        self.fn = fn

    def run(self, stat: DiagnosticStatusWrapper) -> DiagnosticStatusWrapper:
        return self.fn(stat)


class CompositeDiagnosticTask(DiagnosticTask):
    """Several tasks filling one status: their values accumulate, their summaries merge."""

    def __init__(self, name: str) -> None:
        DiagnosticTask.__init__(self, name)
        self.tasks: List[DiagnosticTask] = []

    def run(self, stat: DiagnosticStatusWrapper) -> DiagnosticStatusWrapper:
        combined = DiagnosticStatusWrapper()
        original = DiagnosticStatusWrapper()
        original.summary(stat)
        for task in self.tasks:
            stat.summary(original)  # each task starts from the summary passed in
            stat = task.run(stat)
            combined.mergeSummary(stat)
        stat.summary(combined)
        return stat

    def addTask(self, t: DiagnosticTask) -> None:
        self.tasks.append(t)


class DiagnosticTaskVector:
    """A list of named tasks (base of Updater)."""

    class DiagnosticTaskInternal:
        def __init__(self, name: str, fn: Callable) -> None:
            self.name = name
            self.fn = fn

        def run(self, stat: DiagnosticStatusWrapper) -> Any:
            stat.name = self.name
            return self.fn(stat)

    def __init__(self) -> None:
        self.tasks: List[DiagnosticTaskVector.DiagnosticTaskInternal] = []
        self.lock = threading.Lock()

    def addedTaskCallback(self, task: Any) -> None:
        """Called for each added task (Updater publishes "Node starting up")."""

    def add(self, *args: Any) -> None:
        """``add(task)`` or ``add(name, fn)``."""
        if len(args) == 1:
            task = self.DiagnosticTaskInternal(args[0].getName(), args[0].run)
        elif len(args) == 2:
            task = self.DiagnosticTaskInternal(args[0], args[1])
        else:
            raise TypeError("add() takes a DiagnosticTask, or a name and a function")
        with self.lock:
            self.tasks.append(task)
            self.addedTaskCallback(task)

    def removeByName(self, name: str) -> bool:
        """Remove the first task called ``name``; whether one was."""
        with self.lock:
            for i, task in enumerate(self.tasks):
                if task.name == name:
                    del self.tasks[i]
                    return True
        return False


class Updater(DiagnosticTaskVector):
    """Runs its tasks at most every ``~diagnostic_period`` seconds (default 1) when
    :meth:`update` is called, and publishes their statuses on ``/diagnostics``, each named
    ``<node name>: <task name>``."""

    def __init__(self) -> None:
        DiagnosticTaskVector.__init__(self)
        self.publisher = minros.Publisher("/diagnostics", DiagnosticArray, queue_size=10)
        self.last_time = minros.Time.now()
        self.last_time_period_checked = self.last_time
        self.period = 1
        self.verbose = False
        self.hwid = ""
        self.warn_nohwid_done = False

    def update(self) -> None:
        """Run the tasks if the period has passed since the last run."""
        self._check_diagnostic_period()
        if minros.Time.now() >= self.last_time + minros.Duration(self.period):
            self.force_update()

    def force_update(self) -> None:
        """Run every task now and publish the result."""
        self.last_time = minros.Time.now()
        warn_nohwid = len(self.hwid) == 0
        statuses = []
        with self.lock:
            for task in self.tasks:
                status = DiagnosticStatusWrapper()
                status.name = task.name
                status.level = 2
                status.message = "No message was set"
                status.hardware_id = self.hwid
                task.run(status)
                statuses.append(status)
                if status.level:
                    warn_nohwid = False
                if self.verbose and status.level:
                    minros.logwarn(f"Non-zero diagnostic status. Name: '{status.name}', status "
                                   f"{status.level}: '{status.message}'")
        if warn_nohwid and not self.warn_nohwid_done:
            minros.logwarn("diagnostic_updater: No HW_ID was set. This is probably a bug. Please "
                           "report it. For devices that do not have a HW_ID, set this value to "
                           "'none'. This warning only occurs once all diagnostics are OK so it is "
                           "okay to wait until the device is open before calling setHardwareID.")
            self.warn_nohwid_done = True
        self.publish(statuses)

    def broadcast(self, lvl: int, msg: str) -> None:
        """Publish ``lvl``/``msg`` as the status of every task (e.g. before a shutdown)."""
        statuses = []
        for task in self.tasks:
            status = DiagnosticStatusWrapper()
            status.name = task.name
            status.summary(lvl, msg)
            statuses.append(status)
        self.publish(statuses)

    def setHardwareID(self, hwid: str) -> None:
        self.hwid = hwid

    def _check_diagnostic_period(self) -> None:
        """Re-read ``~diagnostic_period``, at most four times a second."""
        now = minros.Time.now()
        if now >= self.last_time_period_checked + minros.Duration(0.25):
            try:
                self.period = minros.get_param_cached("~diagnostic_period", 1)
                self.last_time_period_checked = now
            except (http.client.CannotSendRequest, http.client.ResponseNotReady):
                pass

    def publish(self, msg: Any) -> None:
        """Publish one status or a list of them (their names get the node name in front)."""
        statuses = msg if type(msg) is list else [msg]
        prefix = minros.get_name()[1:] + ": "
        for stat in statuses:
            stat.name = prefix + stat.name
        array = DiagnosticArray()
        array.status = statuses
        array.header.stamp = minros.Time.now()
        self.publisher.publish(array)

    def addedTaskCallback(self, task: Any) -> None:
        stat = DiagnosticStatusWrapper()
        stat.name = task.name
        stat.summary(0, "Node starting up")
        self.publish(stat)
