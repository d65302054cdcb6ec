"""What every part of the setup page shares: the session, the server, messages, guarded input.

Why a base of its own: the page is one object (every tab shows it), built from one small module
per tab (``page_parts``, ``page_states``, ``page_check``) over this base, so each stays short
and the shared helpers (the guard every callback goes through, the message line) live once.
"""

from __future__ import annotations

import html
import sys
import threading
import traceback
from collections.abc import Callable
from pathlib import Path
from typing import Any

from robotspec.errors import RobotSpecError
from robotspec.setup.session import SetupSession
from robotspec.setup.validation import Problem, Validation

__all__ = ["PageBase", "problem_line"]


def problem_line(p: Problem) -> str:
    """One problem as a line of the page: its icon, part, where, and the message."""
    where = f"line {p.line}" if p.line is not None else ""
    if p.file is not None:
        where = f"{Path(p.file).name}:{p.line}" if p.line is not None else Path(p.file).name
    icon = "✖" if p.severity != "warning" else "⚠"
    return f"- {icon} `{p.part}` {where}: {html.escape(p.message)}"


class PageBase:
    """The state and helpers the page's tabs share (viser handles are ``Any``)."""

    session: SetupSession
    server: Any
    viewer: Any
    _gui_lock: threading.RLock
    _message: Any
    _part: Any
    _state_part: Any

    def _guarded(self, fn: Callable[[Any], None]) -> Callable[[Any], None]:
        """A callback that acts on a person's input only, and reports instead of raising."""

        def run(event: Any) -> None:
            if getattr(event, "client", True) is None:
                return  # a value the server set itself
            self._entered(event)  # which tab acts: its own pick (setup/page_clients.py)
            try:
                fn(event)
            except RobotSpecError as exc:
                self.session.failed(exc.message)  # the next undo says so, and undoes nothing
                near = f" (did you mean {', '.join(exc.suggestions)}?)" if exc.suggestions else ""
                self.say(f"**{exc.severity}:** {html.escape(exc.message)}{near}")
            except Exception as exc:  # noqa: BLE001 - the server outlives any bug in one action
                traceback.print_exc(file=sys.stderr)
                self.say(f"**internal error:** {type(exc).__name__}: {html.escape(str(exc))}")
            finally:
                self._exited()

        return run

    def say(self, text: str) -> None:
        """Show the outcome of the last action."""
        self.last_message = text
        self._message.content = text

    def _after(self, v: Validation, done: str) -> None:
        if v.valid:
            self.say(f"{done}; the spec is valid")
        else:
            shown = "\n".join(problem_line(p) for p in v.errors[:4])
            self.say(f"{done}; **the spec is now invalid:**\n\n{shown}")

    def _button(self, gui: Any, label: str, action: Callable[[], None]) -> Any:
        b = gui.add_button(label)
        b.on_click(self._guarded(lambda _e: action()))
        return b

    def _pick(self) -> str:
        link = self.selected
        if link is None:
            raise RobotSpecError("pick a link first (click the robot, or choose it above)")
        return link

    # ------------------------------------------------------------------ the tabs (clients)
    @property
    def selected(self) -> str | None:
        """The picked link of the tab acting now (setup/page_clients.py)."""
        raise NotImplementedError

    def select(self, link: str) -> None:
        """Pick a link for the tab acting now."""
        raise NotImplementedError

    def _entered(self, event: Any) -> None:
        """A tab's callback starts on this thread."""
        raise NotImplementedError

    def _exited(self) -> None:
        """That callback ended."""
        raise NotImplementedError

    # ------------------------------------------------------------------ the tabs' own
    def _select_part(self, part: str) -> None:
        """Show the controls of ``part`` (the parts tab)."""
        raise NotImplementedError

    def _show_part_info(self) -> None:
        """Describe the chosen part (the parts tab)."""
        raise NotImplementedError

    def _state_holders(self) -> tuple[str, ...]:
        """The parts a state may belong to (the states tab)."""
        raise NotImplementedError

    def _show_sliders(self) -> None:
        """A slider per joint of the chosen part (the states tab)."""
        raise NotImplementedError

    def _show_saved_states(self) -> None:
        """The chosen part's saved states (the states tab)."""
        raise NotImplementedError
