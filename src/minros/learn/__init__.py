"""``minros learn``: short exercises on the ROS 1 wire that check themselves.

Each exercise starts what it needs (masters and small nodes, every process traced), asks one
question the wire answers, and checks the learner's answer against the learner's own trace,
with a hint when it is not right yet. The exercises are data (:mod:`.catalog`), the checkers
pure functions; :mod:`.session` does the I/O (folders, processes) and ``minros learn`` (in
``minros.cli.learn``) is the command line. A page view needs only this API:

    exercises()                               every exercise, numbered from 1
    exercise(number)                          one (LookupError when there is none)
    task(number, facts)                       its task text, for the facts of one start
    check(number, answer, traces, facts)      -> Result(ok, text, hint, details)

``traces`` maps a trace file's name (``master``, ``talker``, ...; ``me`` for the learner's
own) to its events, ``facts`` is what the start recorded (``state.json``).
"""

from __future__ import annotations

from typing import Any, Dict, List, Mapping, Tuple

from minros.learn.model import Attempt, Exercise, Process, Result

__all__ = ["Attempt", "Exercise", "Process", "Result", "check", "exercise", "exercises", "task"]


def exercises() -> Tuple[Exercise, ...]:
    from minros.learn.catalog import EXERCISES

    return EXERCISES


def exercise(number: int) -> Exercise:
    for item in exercises():
        if item.number == number:
            return item
    raise LookupError(f"there is no exercise {number}: minros learn --list shows the "
                      f"{len(exercises())} exercises")


def task(number: int, facts: Mapping[str, Any]) -> str:
    return exercise(number).task_text(facts)


def check(number: int, answer: str, traces: Mapping[str, List[Dict[str, Any]]],
          facts: Mapping[str, Any]) -> Result:
    """Check ``answer`` to exercise ``number`` against ``traces``."""
    return exercise(number).check(Attempt(answer, traces, dict(facts, number=number)))
