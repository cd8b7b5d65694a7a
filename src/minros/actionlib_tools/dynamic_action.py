"""DynamicAction: the message classes of an action type named at run time."""

from __future__ import annotations

from minros.msgs import get_message_class

__all__ = ["DynamicAction"]


class DynamicAction:
    """``DynamicAction('actionlib/TwoIntsAction')``: ``action``, ``goal``, ``feedback`` and
    ``result`` classes; a ValueError names a type that is not an action or not installed."""

    def __init__(self, name: str) -> None:
        if not name.endswith("Action"):
            raise ValueError(f"{name} is not an action type: its name must end in 'Action' "
                             "(pkg/NameAction)")
        self.name = name[: -len("Action")]
        self.action = self.load_submsg("Action")
        self.goal = self.load_submsg("Goal")
        self.feedback = self.load_submsg("Feedback")
        self.result = self.load_submsg("Result")

    def load_submsg(self, subname: str) -> type:
        try:
            return get_message_class(self.name + subname)
        except Exception as exc:  # noqa: BLE001 - the registry's own error, one line
            raise ValueError(f"Could not load message for: {self.name + subname} ({exc})") from None
