"""The check tab's accepted warnings: each ``accept_warnings`` entry, its reason changed or removed.

Why beside *accept a warning*: an entry written before (by a person, or by this page another
day) is as much the spec's as a new one; a reason goes stale, and a warning accepted by mistake
must be able to come back. Changes are made in the entry's own lines (``setup/edits_more.py``).
"""

from __future__ import annotations

import html
from typing import Any

from robotspec.errors import RobotSpecError
from robotspec.setup.page_base import PageBase
from robotspec.setup.page_more import at_input

__all__ = ["AcceptedPart"]

NO_ENTRY = "(no accepted warning)"


class AcceptedPart(PageBase):
    """The accepted warnings of the check & save tab."""

    def _build_accepted(self, gui: Any) -> None:
        with gui.add_folder("accepted warnings"):
            self._acc_pick = gui.add_dropdown("accepted warning", (NO_ENTRY,))
            self._acc_pick.on_update(self._guarded(lambda _e: self._show_accepted()))
            self._acc_info = gui.add_markdown("")
            self._acc_reason = gui.add_text("new reason", "")
            self._acc_note = gui.add_markdown("")
            self._button(gui, "change the reason", at_input(self._acc_note, self._reason))
            self._button(gui, "remove the entry", at_input(self._acc_note, self._unaccept))

    def _entries(self) -> dict[str, tuple[str, str, str]]:
        return {f"{a}: {s}": (a, s, b) for a, s, b in self.session.accepted_entries()}

    def _show_accepted(self) -> None:
        entries = self._entries()
        labels = tuple(entries) or (NO_ENTRY,)
        if tuple(self._acc_pick.options) != labels:
            self._acc_pick.options = labels
        entry = entries.get(str(self._acc_pick.value))
        self._acc_info.content = f"<small>because: {html.escape(entry[2])}</small>" if entry else ""

    def _chosen(self) -> tuple[str, str, str]:
        entry = self._entries().get(str(self._acc_pick.value))
        if entry is None:
            raise RobotSpecError("the spec accepts no warning: accept one above first")
        return entry

    def _reason(self) -> None:
        at, says, _ = self._chosen()
        v = self.session.set_accepted_reason(at, says, str(self._acc_reason.value))
        self._acc_reason.value = ""
        self._after(v, f"{html.escape(at)}: reason changed")

    def _unaccept(self) -> None:
        at, says, _ = self._chosen()
        v = self.session.remove_accepted(at, says)
        self._after(v, f"{html.escape(at)}: no longer accepted; validate warns of it again")
