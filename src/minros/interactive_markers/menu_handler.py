"""MenuHandler: a marker's context menu (entries, sub-menus, check boxes) and its feedback."""

from __future__ import annotations

from typing import Any, Callable, Dict, List, Optional, Set

import minros
from visualization_msgs.msg import InteractiveMarkerFeedback, MenuEntry

__all__ = ["MenuHandler", "EntryContext"]


class EntryContext:
    def __init__(self) -> None:
        self.title = ""
        self.command = ""
        self.command_type = 0
        self.sub_entries: List[int] = []
        self.visible = True
        self.check_state = 0
        self.feedback_cb: Optional[Callable[[Any], None]] = None


class MenuHandler:
    """Entries are numbered from 1 (their handle, which is the MenuEntry id rviz sends back);
    ``apply(server, marker_name)`` puts the menu on a marker and routes its selections."""

    NO_CHECKBOX = 0
    CHECKED = 1
    UNCHECKED = 2

    def __init__(self) -> None:
        self.top_level_handles_: List[int] = []
        self.entry_contexts_: Dict[int, EntryContext] = {}
        self.current_handle_ = 1
        self.managed_markers_: Set[str] = set()

    def insert(self, title: str, parent: Optional[int] = None,
               command_type: int = MenuEntry.FEEDBACK, command: str = "",
               callback: Optional[Callable[[Any], None]] = None) -> Optional[int]:
        """Add an entry (under ``parent``'s sub-menu if given); its handle, or None when the
        parent does not exist."""
        if parent is not None and parent not in self.entry_contexts_:
            minros.logerr(f"Parent menu entry {parent} not found.")
            return None
        handle = self.current_handle_
        self.current_handle_ += 1
        context = EntryContext()
        context.title = title
        context.command = command
        context.command_type = command_type
        context.feedback_cb = callback
        self.entry_contexts_[handle] = context
        if parent is not None:
            self.entry_contexts_[parent].sub_entries.append(handle)
        else:
            self.top_level_handles_.append(handle)
        return handle

    def setVisible(self, handle: int, visible: bool) -> bool:
        context = self.entry_contexts_.get(handle)
        if context is None:
            return False
        context.visible = visible
        return True

    def setCheckState(self, handle: int, check_state: int) -> bool:
        context = self.entry_contexts_.get(handle)
        if context is None:
            return False
        context.check_state = check_state
        return True

    def getCheckState(self, handle: int) -> Optional[int]:
        context = self.entry_contexts_.get(handle)
        return context.check_state if context is not None else None

    def getTitle(self, handle: int) -> Optional[str]:
        context = self.entry_contexts_.get(handle)
        return context.title if context is not None else None

    def apply(self, server: Any, marker_name: str) -> bool:
        """Write the menu into the marker (re-inserted into ``server``; applyChanges
        publishes it). False when the server has no such marker."""
        marker = server.get(marker_name)
        if not marker:
            self.managed_markers_.discard(marker_name)
            return False
        marker.menu_entries = []
        self._push(self.top_level_handles_, marker.menu_entries, 0)
        server.insert(marker, self.processFeedback, InteractiveMarkerFeedback.MENU_SELECT)
        self.managed_markers_.add(marker_name)
        return True

    def reApply(self, server: Any) -> bool:
        """Apply the menu again to every marker it was applied to (after a change)."""
        ok = True
        for name in list(self.managed_markers_):
            ok = self.apply(server, name) and ok
        return ok

    def processFeedback(self, feedback: Any) -> None:
        context = self.entry_contexts_.get(feedback.menu_entry_id)
        if context is not None and context.feedback_cb is not None:
            context.feedback_cb(feedback)

    def _push(self, handles: List[int], out: List[Any], parent: int) -> None:
        for handle in handles:
            context = self.entry_contexts_[handle]
            if not context.visible:
                continue
            out.append(self._entry(context, handle, parent))
            self._push(context.sub_entries, out, handle)

    def _entry(self, context: EntryContext, handle: int, parent: int) -> Any:
        prefix = {self.CHECKED: "[x] ", self.UNCHECKED: "[ ] "}.get(context.check_state, "")
        return MenuEntry(id=handle, parent_id=parent, title=prefix + context.title,
                         command=context.command, command_type=context.command_type)
