"""The page's check & save tab: validate's problems, the collision matrix, save; undo, redo."""

from __future__ import annotations

import html
import sys
import threading
import time
import traceback
from pathlib import Path
from typing import Any

from robotspec.errors import RobotSpecError
from robotspec.setup.accept import acceptances
from robotspec.setup.collisions import AuditReport
from robotspec.setup.page_matrix import MatrixPart
from robotspec.setup.validation import Validation

__all__ = ["NO_WARNING", "CheckTab"]

#: The warning list's one entry when no warning can be accepted.
NO_WARNING = "(no warning to accept)"


class CheckTab(MatrixPart):
    """The check & save tab of :class:`~robotspec.setup.page.SetupPage`."""

    _audit_report: AuditReport | None
    _busy: bool
    _busy_lock: threading.Lock

    def _build_accepted(self, gui: Any) -> None:
        """The accepted warnings' folder (``page_accepted``)."""
        raise NotImplementedError

    def _build_check(self, gui: Any) -> None:
        self._problems = gui.add_markdown("")
        with gui.add_folder("accept a warning"):
            gui.add_markdown(
                "<small>A warning that is right for this robot, accepted with your reason: "
                "an `accept_warnings` entry (new lines at the end of the spec; undo takes it "
                "back).</small>"
            )
            self._accept_pick = gui.add_dropdown("warning", (NO_WARNING,))
            self._because = gui.add_text("because", "")
            self._because_note = gui.add_markdown("")
            self._button(gui, "accept with reason", self._accept)
        self._build_accepted(gui)
        with gui.add_folder("self-collision matrix"):
            self._samples = gui.add_number("samples", 2000, min=100, max=1_000_000, step=100)
            self._button(gui, "generate collision matrix", lambda: self._collisions("generate"))
            self._button(gui, "audit the SRDF", lambda: self._collisions("audit"))
            self._progress = gui.add_progress_bar(0.0, visible=False)
            self._collision_text = gui.add_markdown(
                "The generated SRDF stays here until *save*, which writes it beside the spec "
                "(never over the robot's own SRDF)."
            )
            self._build_matrix(gui)
        self._save_path = gui.add_text("save as", str(self.session.output))
        where = ", ".join(f"`{html.escape(str(f))}`" for f in self.session.fence.folders)
        gui.add_markdown(f"<small>save as writes inside {where} only</small>")
        self._button(gui, "save", self._save)

    def _show_acceptable(self, v: Validation) -> None:
        """List the warnings an entry can accept now (an accepted one is gone from validate)."""
        labels = tuple(a.label for a in acceptances(v)) or (NO_WARNING,)
        if tuple(self._accept_pick.options) != labels:
            self._accept_pick.options = labels

    def _accept(self) -> None:
        """Accept the chosen warning; an empty reason is refused at its box, saying why."""
        warning = str(self._accept_pick.value)
        if warning == NO_WARNING:
            raise RobotSpecError("validate prints no warning an entry can accept now")
        try:
            v = self.session.accept_warning(warning, str(self._because.value))
        except RobotSpecError as exc:
            self._because_note.content = f"<small>**refused:** {html.escape(exc.message)}</small>"
            raise
        self._because_note.content = ""
        self._because.value = ""
        self._after(v, f"accepted {html.escape(warning)}")

    def _stepped(self, *, back: bool) -> None:
        """Undo or redo one change (any tab's), saying which (Ctrl+Z, Ctrl+Shift+Z press these)."""
        v, said = self.session.step(back=back)
        if said.startswith(("undone", "redone")):
            self._after(v, html.escape(said))
        else:
            self.say(html.escape(said))

    def _collisions(self, what: str) -> None:
        from robotspec.setup.collisions import audit_session, generate_matrix, plain_audit_report

        with self._busy_lock:
            if self._busy:
                raise RobotSpecError("the collision check is running; wait for it to finish")
            self._busy = True
        samples = int(self._samples.value)
        self._progress.visible = True
        self._progress.value = 0.0
        self._collision_text.content = f"{what}: running..."
        last = [0.0]

        def progress(done: int, total: int) -> None:
            now = time.monotonic()
            if now - last[0] > 0.2 or done >= total:
                last[0] = now
                self._progress.value = 100.0 * done / max(total, 1)

        def work() -> None:
            try:
                if what == "generate":
                    r = generate_matrix(self.session, samples=samples, progress=progress)
                    self._collision_text.content = r.summary
                    self._show_pairs()
                else:
                    report = self._audit_report or plain_audit_report
                    ok, text = audit_session(
                        self.session, samples=samples, progress=progress, report=report
                    )
                    head = "every entry is right" if ok else "**some entries are wrong**"
                    self._collision_text.content = f"{head}\n\n```\n{text}\n```"
            except RobotSpecError as exc:
                self._collision_text.content = f"**error:** {html.escape(exc.message)}"
            except Exception as exc:  # noqa: BLE001 - a bug must not end the server
                traceback.print_exc(file=sys.stderr)
                self._collision_text.content = f"**internal error:** {type(exc).__name__}: {exc}"
            finally:
                self._progress.value = 100.0
                with self._busy_lock:
                    self._busy = False

        threading.Thread(target=work, name=f"setup-{what}", daemon=True).start()

    def _save(self) -> None:
        typed = str(self._save_path.value).strip()
        if not typed:
            raise RobotSpecError(
                f"'save as' is empty: give the file to write, a .yaml or .yml name "
                f"(the output is {self.session.output})",
                kind="file",
            )
        path = self.session.save(Path(typed).expanduser())
        self.say(f"saved **{html.escape(str(path))}**; `robotspec validate {path}` accepts it")
