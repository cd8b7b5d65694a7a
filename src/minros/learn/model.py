"""What an exercise is, as data: what it starts, what it asks, how an answer is checked.

An :class:`Exercise` names the processes it starts (:class:`Process`: a master, a small
node of :mod:`minros.learn.actors` or a minros program such as ``minros zenoh``, each traced
to its own file unless told not to), the task text (a template filled with the facts of one
start: ports, URIs, the folder, the random values it chose), and a checker: a pure function
from an :class:`Attempt` (the learner's answer, the traces in the exercise's folder, the
facts) to a :class:`Result` (right or not, what was found, a hint). An exercise may come in
variants (exercise 11: through Zenoh or a relay), each with its processes and facts; the
default is the first that can start here (one needing a package that is not installed
cannot).
"""

from __future__ import annotations

import random
import re
from dataclasses import dataclass, field
from typing import Any, Callable, Dict, List, Mapping, Optional, Sequence, Tuple

__all__ = ["Attempt", "Exercise", "Process", "Result", "tokens"]

#: events of one trace file (JSON objects, as minros.wire.trace writes them)
Events = List[Dict[str, Any]]


@dataclass(frozen=True)
class Process:
    """A process an exercise starts, traced to ``<name>.jsonl`` in the exercise's folder.

    ``argv`` follows ``python -m`` (``minros core`` for a master, ``minros.learn.actors ROLE``
    for a node), with ``{port}``-style fields filled from the facts. ``master`` says which
    master (``a`` or ``b``) its ROS_MASTER_URI names; a master process serves it. ``ready``
    is what its trace must show before the exercise is ready: ``("master",)`` (the master
    answers), or ``(method, name)``: a call of ``method`` about topic or service ``name``
    that got its reply. ``stdin_from`` pipes another process's output into this one.
    ``traced`` False runs it untraced (its output still goes to ``<name>.log``): a process
    whose peers' traces already show all it does, and whose own would only grow; ``node``,
    its ROS name, is then what its master must list for ``ready``."""

    name: str
    argv: Tuple[str, ...]
    master: str = "a"
    ready: Tuple[str, ...] = ()
    stdin_from: str = ""
    stdout_pipe: bool = False
    traced: bool = True
    node: str = ""


@dataclass
class Attempt:
    """What a checker sees: the answer as typed, the trace files of the exercise's folder by
    name (``me`` is the learner's: every ``me*.jsonl`` together), and the facts of the start."""

    answer: str
    traces: Mapping[str, Events]
    facts: Mapping[str, Any]

    @property
    def mine(self) -> Events:
        return list(self.traces.get("me", []))

    @property
    def words(self) -> List[str]:
        return tokens(self.answer)


@dataclass
class Result:
    """A checker's verdict: ``text`` says what it found, ``hint`` where to look when the
    answer is not right yet, ``details`` extra lines (figures measured in the traces)."""

    ok: bool
    text: str
    hint: str = ""
    details: List[str] = field(default_factory=list)


Checker = Callable[[Attempt], Result]


@dataclass(frozen=True)
class Exercise:
    """One exercise: at most ``minutes`` of work on one thing the wire shows."""

    number: int
    slug: str
    title: str
    minutes: int
    covers: str
    #: what ``minros learn N`` prints (a template over the facts)
    task: str
    #: how to answer, e.g. ``URI...`` (shown in the list and by ``check`` without an answer)
    answer_form: str
    check: Checker
    #: processes to start, by variant (the first is the default): ``{"": (...)}`` for one
    variants: Mapping[str, Tuple[Process, ...]] = field(default_factory=lambda: {"": ()})
    #: random choices of one start (``facts(rng)``): values to find, names to vary
    choose: Optional[Callable[[random.Random], Dict[str, Any]]] = None
    #: files written into the folder at start: name -> template over the facts
    files: Mapping[str, str] = field(default_factory=dict)
    #: variants named but not available yet, with the reason
    planned: Mapping[str, str] = field(default_factory=dict)
    #: variants that need something this installation may lack: variant -> a function
    #: returning what is missing and how to get it ("" when nothing is)
    requires: Mapping[str, Callable[[], str]] = field(default_factory=dict)
    #: facts a variant adds to each start (texts of its task, ``answer_form`` when its
    #: answer differs); their strings are templates over the facts too
    variant_facts: Mapping[str, Mapping[str, Any]] = field(default_factory=dict)

    def missing(self, variant: str) -> str:
        """Why ``variant`` cannot start here ("" when it can)."""
        if variant in self.planned:
            return self.planned[variant]
        need = self.requires.get(variant)
        return need() if need is not None else ""

    @property
    def default_variant(self) -> str:
        """The first variant that can start here (the first of all when none can)."""
        return next((v for v in self.variants if not self.missing(v)), next(iter(self.variants)))

    def unavailable(self) -> Dict[str, str]:
        """The variants named but not startable here, with the reason."""
        named = [*self.variants, *(v for v in self.planned if v not in self.variants)]
        return {v: reason for v in named if (reason := self.missing(v))}

    def processes(self, variant: str = "") -> Tuple[Process, ...]:
        return self.variants[variant or self.default_variant]

    def masters(self, variant: str = "") -> List[str]:
        """The masters the exercise starts (``a``, ``b``), in order."""
        return [p.master for p in self.processes(variant) if p.ready[:1] == ("master",)]

    def form(self, variant: str = "") -> str:
        """How ``variant``'s answer is given."""
        extra = self.variant_facts.get(variant or self.default_variant, {})
        return str(extra.get("answer_form", self.answer_form))

    def task_text(self, facts: Mapping[str, Any]) -> str:
        variant = str(facts.get("variant") or self.default_variant)
        extra = {"answer_form": self.form(variant), **self.variant_facts.get(variant, {})}
        known = _Facts({**extra, **facts})
        filled = {k: v.format_map(known) if isinstance(v, str) else v for k, v in extra.items()}
        return self.task.format_map(_Facts({**facts, **filled})).strip("\n")


class _Facts(dict):
    """Facts for a template: a missing one shows as ``<name>`` instead of raising."""

    def __missing__(self, key: str) -> str:
        return f"<{key}>"


_TOKEN = re.compile(r"[^\s,;\[\]()'\"`]+")


def tokens(answer: str) -> List[str]:
    """The words of an answer: split at spaces, commas and semicolons, without the quotes
    and brackets a learner may copy along (a trailing ``/`` of a URI is kept)."""
    return _TOKEN.findall(answer)


def same_uri(a: str, b: str) -> bool:
    """Two URIs the same but for a trailing slash."""
    return a.rstrip("/") == b.rstrip("/")


def find(items: Sequence[Any], predicate: Callable[[Any], bool]) -> Any:
    return next((item for item in items if predicate(item)), None)
